//! A structure's name in other languages, by language tag (BCP 47: "de", "pt-BR"), and the one a
//! reader sees: the name in the first of the reader's languages the structure has one in. The
//! structure's own name stands for English unless it also has an "en" name (the sources we read,
//! Slicer's terminology, TotalSegmentator and FreeSurfer, name structures in English).

use std::collections::BTreeMap;

use serde_json::Value;

use super::Case;

/// Names by language tag, tags in their usual case ("de", "pt-BR", "zh-Hant").
pub type Names = BTreeMap<String, String>;

/// The longest tag taken: BCP 47's longest registered forms are well within it.
const MAX_TAG: usize = 35;

/// `text` as a language tag in its usual case: the language in lower case, a two-letter region
/// in upper case, a four-letter script capitalised; an error says what is wrong.
pub fn tag(text: &str) -> Result<String, String> {
    let text = text.trim();
    let wrong = |why: &str| format!("'{text}' is not a language tag ({why}; e.g. de, pt-BR)");
    if text.is_empty() || text.len() > MAX_TAG {
        return Err(wrong("1 to 35 characters"));
    }
    let mut out = Vec::new();
    for (i, part) in text.split(['-', '_']).enumerate() {
        // The language itself is ISO 639's two or three letters.
        let ok_chars = if i == 0 {
            (2..=3).contains(&part.len()) && part.chars().all(|c| c.is_ascii_alphabetic())
        } else {
            part.chars().all(|c| c.is_ascii_alphanumeric())
        };
        if part.is_empty() || part.len() > 8 || !ok_chars {
            return Err(wrong(
                "a two or three letter language, then letters, digits and hyphens",
            ));
        }
        let alpha = part.chars().all(|c| c.is_ascii_alphabetic());
        out.push(match (i, part.len()) {
            (0, _) => part.to_ascii_lowercase(),
            (_, 2) if alpha => part.to_ascii_uppercase(),
            (_, 4) if alpha => part[..1].to_ascii_uppercase() + &part[1..].to_ascii_lowercase(),
            _ => part.to_ascii_lowercase(),
        });
    }
    Ok(out.join("-"))
}

/// The language a tag names, without region or script ("pt" of "pt-BR").
fn language(tag: &str) -> &str {
    tag.split(['-', '_']).next().unwrap_or(tag)
}

/// `names` with each tag in its usual case and each name trimmed; an empty name, a bad tag or
/// two names in one language (tags differing in case) is an error.
pub fn checked(names: &Names) -> Result<Names, String> {
    let mut out = Names::new();
    for (t, name) in names {
        let name = name.trim();
        if name.is_empty() {
            return Err(format!("the name in '{t}' is empty"));
        }
        let tag = tag(t)?;
        if out.insert(tag.clone(), name.to_string()).is_some() {
            return Err(format!("two names in '{tag}'"));
        }
    }
    Ok(out)
}

/// Names from JSON: an object of language tag to name.
pub fn from_json(value: &Value) -> Result<Names, String> {
    let object = (value.as_object()).ok_or("names must be an object of language tag to name")?;
    let names = (object.iter())
        .map(|(t, v)| match v.as_str() {
            Some(name) => Ok((t.clone(), name.to_string())),
            None => Err(format!("the name in '{t}' is not text")),
        })
        .collect::<Result<Names, String>>()?;
    checked(&names)
}

/// Names as one line to edit: `de: Leber; fr: Foie`.
pub fn to_line(names: &Names) -> String {
    (names.iter())
        .map(|(t, n)| format!("{t}: {n}"))
        .collect::<Vec<_>>()
        .join("; ")
}

/// Names from a line as [`to_line`] writes it; an empty line is no names.
pub fn from_line(line: &str) -> Result<Names, String> {
    let mut names = Names::new();
    for part in line.split(';').filter(|p| !p.trim().is_empty()) {
        let (t, name) = (part.split_once(':')).ok_or_else(|| {
            format!(
                "'{}': write a language tag, a colon and the name",
                part.trim()
            )
        })?;
        if names
            .insert(t.trim().to_string(), name.to_string())
            .is_some()
        {
            return Err(format!("two names in '{}'", t.trim()));
        }
    }
    checked(&names)
}

/// Gives the case's structures the names of a table (JSON: each structure's name to its names
/// by language tag, `{"Liver": {"de": "Leber"}}`); a structure the table leaves out keeps its
/// own. A name the case does not have is an error, and then nothing changes.
pub fn apply_table(case: &mut Case, table: &[u8]) -> Result<(), String> {
    let table: Value =
        serde_json::from_slice(table).map_err(|e| format!("not a table of names: {e}"))?;
    let object = (table.as_object())
        .ok_or("not a table of names: an object of structure name to names is expected")?;
    let mut found = Vec::new();
    for (structure, names) in object {
        let index = (case.structures.iter().position(|s| &s.name == structure))
            .ok_or_else(|| format!("no structure is named '{structure}' in the case"))?;
        let names = from_json(names).map_err(|e| format!("'{structure}': {e}"))?;
        found.push((index, names));
    }
    for (index, names) in found {
        case.structures[index].names = names;
    }
    Ok(())
}

/// The name a reader of `languages` (most wanted first) sees: the structure's name in the first
/// of them it has one in, the exact tag before another region or script of the language; its
/// own name where English comes first or none is there.
pub fn pick<'a>(own: &'a str, names: &'a Names, languages: &[String]) -> &'a str {
    found(names, languages).unwrap_or(own)
}

/// The name [`pick`] takes from `names`; `None` where it takes the own name.
fn found<'a>(names: &'a Names, languages: &[String]) -> Option<&'a str> {
    for wanted in languages {
        let exact = names.iter().find(|(t, _)| t.eq_ignore_ascii_case(wanted));
        let same = || {
            let lang = language(wanted);
            (names.iter()).find(|(t, _)| language(t).eq_ignore_ascii_case(lang))
        };
        if let Some((_, name)) = exact.or_else(same) {
            return Some(name);
        }
        if language(wanted).eq_ignore_ascii_case("en") {
            return None;
        }
    }
    None
}

/// A lesson label's `text` (with its `texts` in other languages) as a reader of `languages` sees
/// it on a structure named `own` with `names`: the label's own text in the reader's language
/// where it has one; else a text that names the structure (its own name or one of its names, in
/// any case) is its name in the reader's language where it has one; else the author's own.
pub fn label_text<'a>(
    (text, texts): (&'a str, &'a Names),
    (own, names): (&'a str, &'a Names),
    languages: &[String],
) -> &'a str {
    if let Some(translated) = found(texts, languages) {
        return translated;
    }
    let said = text.trim().to_lowercase();
    let names_it = std::iter::once(own)
        .chain(names.values().map(String::as_str))
        .any(|n| n.to_lowercase() == said);
    match names_it {
        true => found(names, languages).unwrap_or(text),
        false => text,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(pairs: &[(&str, &str)]) -> Names {
        (pairs.iter())
            .map(|(t, n)| (t.to_string(), n.to_string()))
            .collect()
    }

    fn langs(list: &[&str]) -> Vec<String> {
        list.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn tags_take_their_usual_case_and_bad_ones_are_refused() {
        assert_eq!(tag(" DE ").unwrap(), "de");
        assert_eq!(tag("pt-br").unwrap(), "pt-BR");
        assert_eq!(tag("zh_hant_tw").unwrap(), "zh-Hant-TW");
        assert_eq!(tag("es-419").unwrap(), "es-419");
        for bad in [
            "",
            "d e",
            "de-",
            "1de",
            "de-toolongsubtag",
            "Leber",
            &"a-b".repeat(20),
        ] {
            let e = tag(bad).unwrap_err();
            assert!(e.contains("not a language tag"), "{bad}: {e}");
        }
    }

    #[test]
    fn the_first_language_with_a_name_wins_and_english_is_the_own_name() {
        let n = names(&[("de", "Leber"), ("fr", "Foie"), ("pt-BR", "Fígado")]);
        assert_eq!(pick("Liver", &n, &langs(&["de-AT", "en"])), "Leber");
        assert_eq!(pick("Liver", &n, &langs(&["it", "fr-CA"])), "Foie");
        assert_eq!(pick("Liver", &n, &langs(&["en-US", "de"])), "Liver");
        assert_eq!(pick("Liver", &n, &langs(&["pt-PT"])), "Fígado");
        assert_eq!(pick("Liver", &n, &langs(&["ja"])), "Liver");
        assert_eq!(pick("Liver", &n, &[]), "Liver");
        // A case named in German with an English name: English readers get that one.
        let german = names(&[("en", "Liver")]);
        assert_eq!(pick("Leber", &german, &langs(&["en-GB", "de"])), "Liver");
        assert_eq!(pick("Leber", &german, &langs(&["de"])), "Leber");
        // The exact tag before another region of the language.
        let two = names(&[("pt-BR", "Fígado"), ("pt-PT", "Fígado (PT)")]);
        assert_eq!(pick("Liver", &two, &langs(&["pt-PT"])), "Fígado (PT)");
    }

    #[test]
    fn a_label_naming_its_structure_follows_the_reader_and_other_words_stay() {
        let n = names(&[("en", "Liver"), ("de", "Leber")]);
        let (de, none) = (langs(&["de"]), Names::new());
        assert_eq!(label_text(("Liver", &none), ("liver", &n), &de), "Leber");
        assert_eq!(label_text(("liver ", &none), ("liver", &n), &de), "Leber");
        let english = langs(&["en"]);
        assert_eq!(
            label_text(("LEBER", &none), ("liver", &n), &english),
            "Liver"
        );
        assert_eq!(label_text(("Liver", &none), ("liver", &n), &[]), "Liver");
        assert_eq!(
            label_text(("Liver", &none), ("liver", &n), &langs(&["ja"])),
            "Liver"
        );
        let words = "Segment VIII of the liver";
        assert_eq!(label_text((words, &none), ("liver", &n), &de), words);
        assert_eq!(label_text(("Liver", &none), ("liver", &none), &de), "Liver");
        // The label's own text in the reader's language comes first.
        let own = names(&[("de", "Segment VIII der Leber")]);
        let segment = (words, &own);
        assert_eq!(
            label_text(segment, ("liver", &n), &de),
            "Segment VIII der Leber"
        );
        assert_eq!(label_text(segment, ("liver", &n), &english), words);
        let liver = ("Liver", &own);
        assert_eq!(
            label_text(liver, ("liver", &n), &de),
            "Segment VIII der Leber"
        );
        assert_eq!(label_text(liver, ("liver", &n), &langs(&["fr"])), "Liver");
    }

    #[test]
    fn a_table_names_the_case_structures_or_changes_nothing() {
        let mesh = crate::mesh::Mesh::new(vec![[0.0; 3]; 3], vec![[0, 1, 2]]);
        let mut case = Case::default();
        for name in ["Liver", "Tumour"] {
            let s = super::super::CaseStructure::from_mesh(name, mesh.clone(), [1.0; 3]);
            case.structures.push(s);
        }
        let table = br#"{"Liver": {"de": "Leber", "fr": "Foie"}}"#;
        apply_table(&mut case, table).unwrap();
        assert_eq!(
            case.structures[0].names,
            names(&[("de", "Leber"), ("fr", "Foie")])
        );
        assert!(case.structures[1].names.is_empty());
        let before = case.clone();
        let bad = br#"{"Tumour": {"de": "Tumor"}, "Spleen": {"de": "Milz"}}"#;
        assert!(apply_table(&mut case, bad)
            .unwrap_err()
            .contains("'Spleen'"));
        let bad_tag = br#"{"Tumour": {"Tumor": "de"}}"#;
        assert!(apply_table(&mut case, bad_tag)
            .unwrap_err()
            .contains("'Tumour'"));
        assert!(apply_table(&mut case, b"[1]")
            .unwrap_err()
            .contains("not a table"));
        assert!(apply_table(&mut case, b"{")
            .unwrap_err()
            .contains("not a table"));
        assert_eq!(case, before);
    }

    #[test]
    fn names_read_from_json_and_a_line_and_are_written_back() {
        let json = serde_json::json!({"DE": " Leber ", "fr": "Foie"});
        let n = from_json(&json).unwrap();
        assert_eq!(n, names(&[("de", "Leber"), ("fr", "Foie")]));
        assert_eq!(to_line(&n), "de: Leber; fr: Foie");
        assert_eq!(from_line(&to_line(&n)).unwrap(), n);
        assert_eq!(from_line("  ").unwrap(), Names::new());
        assert!(from_json(&serde_json::json!(["de"])).is_err());
        assert!(from_json(&serde_json::json!({"de": 3}))
            .unwrap_err()
            .contains("'de'"));
        assert!(from_json(&serde_json::json!({"de": " "}))
            .unwrap_err()
            .contains("empty"));
        let twice = serde_json::json!({"de": "Leber", "DE": "Leber"});
        assert!(from_json(&twice).unwrap_err().contains("two names in 'de'"));
        assert!(from_line("de Leber").unwrap_err().contains("colon"));
        assert!(from_line("de: a; de: b")
            .unwrap_err()
            .contains("two names in 'de'"));
        assert!(from_line("x y: Leber")
            .unwrap_err()
            .contains("not a language tag"));
    }
}
