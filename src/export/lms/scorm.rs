//! SCORM's `imsmanifest.xml`: one organization of one item, played by one SCO (the launch
//! page) that lists every file of the package. SCORM 1.2 follows IMS Content Packaging 1.1.2
//! with ADL's `adlcp_rootv1p2` extensions; SCORM 2004 (4th edition) IMS CP 1.1.4 with ADL's
//! `adlcp_v1p3` and IMS Simple Sequencing for the pass mark.

use super::{xml_text, About};

/// The manifest's, organization's, item's and resource's identifiers. The manifest's is the
/// case's, so a package made again of the same case updates the course it made before.
fn identifier(about: &About) -> String {
    // An XML ID: a letter first, then letters, digits, `-`, `_` and `.`.
    let tail = about.id.rsplit(':').next().unwrap_or("case");
    format!("meshsmooth-{tail}")
}

/// The manifest's end, the same in both versions but for the SCO attribute's spelling
/// (`scormtype` in 1.2, `scormType` in 2004): one organization of one item (`item_more` after
/// its title: the mastery or the sequencing), played by the launch page, which lists `files`.
fn organization(about: &About, item_more: &str, scorm_type: &str, files: &[&str]) -> String {
    let id = identifier(about);
    let title = xml_text(&about.title);
    let files: String = (files.iter())
        .map(|f| format!("      <file href=\"{}\"/>\n", xml_text(f)))
        .collect();
    format!(
        r#"  <organizations default="{id}-organization">
    <organization identifier="{id}-organization">
      <title>{title}</title>
      <item identifier="{id}-item" identifierref="{id}-sco" isvisible="true">
        <title>{title}</title>
{item_more}      </item>
    </organization>
  </organizations>
  <resources>
    <resource identifier="{id}-sco" type="webcontent" adlcp:{scorm_type}="sco" href="index.html">
{files}    </resource>
  </resources>
</manifest>
"#
    )
}

/// SCORM 1.2: the pass mark as `adlcp:masteryscore` (0 to 100), the description in the
/// manifest's IMS metadata.
pub(super) fn manifest_12(about: &About, files: &[&str]) -> String {
    let title = xml_text(&about.title);
    let description = xml_text(&about.description);
    let mastery = about
        .mastery
        .map(|m| {
            format!(
                "        <adlcp:masteryscore>{}</adlcp:masteryscore>\n",
                (m * 100.0).round()
            )
        })
        .unwrap_or_default();
    format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<manifest identifier="{id}" version="1"
    xmlns="http://www.imsproject.org/xsd/imscp_rootv1p1p2"
    xmlns:adlcp="http://www.adlnet.org/xsd/adlcp_rootv1p2"
    xmlns:imsmd="http://www.imsglobal.org/xsd/imsmd_rootv1p2p1"
    xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
    xsi:schemaLocation="http://www.imsproject.org/xsd/imscp_rootv1p1p2 imscp_rootv1p1p2.xsd http://www.imsglobal.org/xsd/imsmd_rootv1p2p1 imsmd_rootv1p2p1.xsd http://www.adlnet.org/xsd/adlcp_rootv1p2 adlcp_rootv1p2.xsd">
  <metadata>
    <schema>ADL SCORM</schema>
    <schemaversion>1.2</schemaversion>
    <imsmd:lom>
      <imsmd:general>
        <imsmd:title><imsmd:langstring xml:lang="en-US">{title}</imsmd:langstring></imsmd:title>
        <imsmd:description><imsmd:langstring xml:lang="en-US">{description}</imsmd:langstring></imsmd:description>
      </imsmd:general>
    </imsmd:lom>
  </metadata>
{organization}"#,
        id = identifier(about),
        organization = organization(about, &mastery, "scormtype", files),
    )
}

/// SCORM 2004 4th edition: the pass mark as the primary objective's
/// `imsss:minNormalizedMeasure` (satisfied by the scaled score), the description in the
/// manifest's LOM metadata.
pub(super) fn manifest_2004(about: &About, files: &[&str]) -> String {
    let title = xml_text(&about.title);
    let description = xml_text(&about.description);
    let sequencing = about
        .mastery
        .map(|m| {
            format!(
                r#"        <imsss:sequencing>
          <imsss:objectives>
            <imsss:primaryObjective objectiveID="quiz" satisfiedByMeasure="true">
              <imsss:minNormalizedMeasure>{}</imsss:minNormalizedMeasure>
            </imsss:primaryObjective>
          </imsss:objectives>
        </imsss:sequencing>
"#,
                super::decimal(m)
            )
        })
        .unwrap_or_default();
    format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<manifest identifier="{id}" version="1"
    xmlns="http://www.imsglobal.org/xsd/imscp_v1p1"
    xmlns:adlcp="http://www.adlnet.org/xsd/adlcp_v1p3"
    xmlns:adlseq="http://www.adlnet.org/xsd/adlseq_v1p3"
    xmlns:adlnav="http://www.adlnet.org/xsd/adlnav_v1p3"
    xmlns:imsss="http://www.imsglobal.org/xsd/imsss"
    xmlns:lom="http://ltsc.ieee.org/xsd/LOM"
    xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
    xsi:schemaLocation="http://www.imsglobal.org/xsd/imscp_v1p1 imscp_v1p1.xsd http://www.adlnet.org/xsd/adlcp_v1p3 adlcp_v1p3.xsd http://www.adlnet.org/xsd/adlseq_v1p3 adlseq_v1p3.xsd http://www.adlnet.org/xsd/adlnav_v1p3 adlnav_v1p3.xsd http://www.imsglobal.org/xsd/imsss imsss_v1p0.xsd http://ltsc.ieee.org/xsd/LOM lom.xsd">
  <metadata>
    <schema>ADL SCORM</schema>
    <schemaversion>2004 4th Edition</schemaversion>
    <lom:lom>
      <lom:general>
        <lom:title><lom:string language="en-US">{title}</lom:string></lom:title>
        <lom:description><lom:string language="en-US">{description}</lom:string></lom:description>
      </lom:general>
    </lom:lom>
  </metadata>
{organization}"#,
        id = identifier(about),
        organization = organization(about, &sequencing, "scormType", files),
    )
}
