//! cmi5's course structure (`cmi5.xml`): one course of one assignable unit, the launch page.
//! Without a quiz the unit is done when completed; with one, when completed or passed, at the
//! quiz's pass mark.

use super::{decimal, xml_text, About};

const NAMESPACE: &str = "https://w3id.org/xapi/profiles/cmi5/v1/CourseStructure.xsd";

pub(super) fn course_structure(about: &About) -> String {
    let title = language_string(&about.title);
    let description = language_string(&about.description);
    let (move_on, mastery) = match about.mastery {
        Some(m) => (
            "CompletedOrPassed",
            format!(" masteryScore=\"{}\"", decimal(m)),
        ),
        None => ("Completed", String::new()),
    };
    let id = xml_text(&about.id);
    format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<courseStructure xmlns="{NAMESPACE}">
  <course id="{id}/course">
    <title>{title}</title>
    <description>{description}</description>
  </course>
  <au id="{id}" moveOn="{move_on}"{mastery} launchMethod="AnyWindow">
    <title>{title}</title>
    <description>{description}</description>
    <url>index.html</url>
  </au>
</courseStructure>
"#
    )
}

fn language_string(text: &str) -> String {
    format!("<langstring lang=\"en-US\">{}</langstring>", xml_text(text))
}
