//! The settings files' unit tests.

use super::settings::number_text;
use super::*;
use crate::conventions::{PartialConventions, Setting, Source};
use crate::judge::{DEFAULT_NORMAL_TOLERANCE_DEGREES, Field, FieldSet, Tolerances};
use crate::suite::CheckOptions;

fn parse(text: &str, path: &str) -> ConfigFile {
    match ConfigFile::parse(text, Path::new(path)) {
        Ok(f) => f,
        Err(e) => panic!("{e}"),
    }
}

fn error(text: &str) -> String {
    match ConfigFile::parse(text, Path::new("suite/sweeptrace.toml")) {
        Ok(_) => panic!("parsed: {text}"),
        Err(e) => e.to_string(),
    }
}

fn file(path: &str, line: usize) -> Source {
    Source::File {
        file: path.to_string(),
        line,
    }
}

#[test]
fn no_file_gives_the_defaults() {
    let s = resolve(&[], Path::new("t.mcap"), &Overrides::default());
    assert_eq!(s, Settings::default());
    assert_eq!(s.tolerances(), Tolerances::default());
    let options = s.check_options(CheckOptions::default());
    assert_eq!(options, CheckOptions::default());
}

#[test]
fn top_level_keys_with_their_lines() {
    let f = parse(
        "fields = [\"kind\", \"alpha\"]\nstrict = true\n\n[tolerances]\nalpha = 1e-4\ncontact = 2\n",
        "a/sweeptrace.toml",
    );
    let s = resolve(&[f], Path::new("a/t.mcap"), &Overrides::default());
    assert_eq!(s.fields.value, FieldSet::of(&[Field::Kind, Field::Alpha]));
    assert_eq!(s.fields.source, file("a/sweeptrace.toml", 1));
    assert_eq!(
        (s.strict.value, s.strict.source.clone()),
        (true, file("a/sweeptrace.toml", 2))
    );
    assert_eq!(s.alpha.value, 1e-4);
    assert_eq!(s.alpha.source, file("a/sweeptrace.toml", 5));
    // An integer is a number too.
    assert_eq!(s.contact.value, 2.0);
    assert_eq!(s.contact.source, file("a/sweeptrace.toml", 6));
    assert_eq!(
        s.normal_degrees,
        Setting::default_value(DEFAULT_NORMAL_TOLERANCE_DEGREES)
    );
    assert_eq!(s.allow_tunnels.source, Source::Default);
    assert!(s.check_options(CheckOptions::default()).fail_on_tunnel);
    assert!(s.check_options(CheckOptions::default()).strict);
}

#[test]
fn nearer_files_override_farther_ones_key_by_key() {
    let far = parse(
        "strict = true\n[tolerances]\nalpha = 1e-3\ncontact = 1e-3\n",
        "root/sweeptrace.toml",
    );
    let near = parse("[tolerances]\nalpha = 1e-4\n", "root/sub/sweeptrace.toml");
    let s = resolve(
        &[near, far],
        Path::new("root/sub/t.mcap"),
        &Overrides::default(),
    );
    assert_eq!(s.alpha.value, 1e-4);
    assert_eq!(s.alpha.source, file("root/sub/sweeptrace.toml", 2));
    assert_eq!(s.contact.value, 1e-3);
    assert_eq!(s.contact.source, file("root/sweeptrace.toml", 4));
    assert_eq!(s.strict.source, file("root/sweeptrace.toml", 1));
}

#[test]
fn a_nearer_file_overrides_a_farther_files_traces_block() {
    let far = parse(
        "[[traces]]\nmatch = \"sub/*.mcap\"\ntolerances = { alpha = 1e-3 }\n",
        "root/sweeptrace.toml",
    );
    let near = parse("[tolerances]\nalpha = 1e-4\n", "root/sub/sweeptrace.toml");
    let s = resolve(
        &[near.clone(), far.clone()],
        Path::new("root/sub/t.mcap"),
        &Overrides::default(),
    );
    assert_eq!(s.alpha.source, file("root/sub/sweeptrace.toml", 2));
    let s = resolve(&[far], Path::new("root/sub/t.mcap"), &Overrides::default());
    assert_eq!(
        (s.alpha.value, s.alpha.source),
        (1e-3, file("root/sweeptrace.toml", 3))
    );
}

#[test]
fn traces_blocks_match_relative_to_the_file_and_the_last_one_wins() {
    let f = parse(
        "[tolerances]\nalpha = 1e-5\n\
         [[traces]]\nmatch = \"rapier/*.mcap\"\nfields = [\"kind\"]\ntolerances = { alpha = 1e-4 }\n\
         [[traces]]\nmatch = \"**/golf*.mcap\"\n[traces.tolerances]\nalpha = 1e-3\n",
        "ex/sweeptrace.toml",
    );
    let none = Overrides::default();
    let s = resolve(std::slice::from_ref(&f), Path::new("ex/other.mcap"), &none);
    assert_eq!(
        (s.alpha.value, s.alpha.source),
        (1e-5, file("ex/sweeptrace.toml", 2))
    );
    assert_eq!(s.fields.source, Source::Default);
    let s = resolve(
        std::slice::from_ref(&f),
        Path::new("ex/rapier/a.mcap"),
        &none,
    );
    assert_eq!(
        (s.alpha.value, s.alpha.source),
        (1e-4, file("ex/sweeptrace.toml", 6))
    );
    assert_eq!(s.fields.source, file("ex/sweeptrace.toml", 5));
    // Both blocks match: the last one wins, key by key.
    let s = resolve(
        std::slice::from_ref(&f),
        Path::new("ex/rapier/golf_1.mcap"),
        &none,
    );
    assert_eq!(
        (s.alpha.value, s.alpha.source),
        (1e-3, file("ex/sweeptrace.toml", 10))
    );
    assert_eq!(s.fields.source, file("ex/sweeptrace.toml", 5));
    // `*` does not cross a folder; the path is normalized first.
    let s = resolve(
        std::slice::from_ref(&f),
        Path::new("ex/rapier/deeper/a.mcap"),
        &none,
    );
    assert_eq!(s.alpha.value, 1e-5);
    let s = resolve(
        std::slice::from_ref(&f),
        Path::new("ex/x/../rapier/./a.mcap"),
        &none,
    );
    assert_eq!(s.alpha.value, 1e-4);
    // A trace outside the file's folder gets its top level only.
    let s = resolve(std::slice::from_ref(&f), Path::new("rapier/a.mcap"), &none);
    assert_eq!(s.alpha.value, 1e-5);
}

#[test]
fn the_command_line_overrides_every_file() {
    let f = parse(
        "strict = true\nallow_tunnels = true\nfields = [\"kind\"]\n[tolerances]\nalpha = 1e-4\n",
        "s/sweeptrace.toml",
    );
    let cli = Overrides {
        alpha: Some(0.5),
        strict: Some(false),
        fields: Some(FieldSet::ALL),
        ..Overrides::default()
    };
    let s = resolve(&[f], Path::new("s/t.mcap"), &cli);
    assert_eq!((s.alpha.value, s.alpha.source), (0.5, Source::CommandLine));
    assert_eq!(
        (s.strict.value, s.strict.source),
        (false, Source::CommandLine)
    );
    assert_eq!(s.fields.value, FieldSet::ALL);
    assert_eq!(s.allow_tunnels.source, file("s/sweeptrace.toml", 2));
}

#[test]
fn unknown_keys_name_file_line_and_column() {
    assert!(
        error("strict = true\nalfa = 1\n")
            .starts_with("suite/sweeptrace.toml:2:1: unknown key `alfa`, expected one of"),
        "{}",
        error("strict = true\nalfa = 1\n")
    );
    let e = error("[tolerances]\n  normal = 1\n");
    assert!(
        e.starts_with("suite/sweeptrace.toml:2:3: unknown key `normal`"),
        "{e}"
    );
    assert!(e.contains("normal_degrees"), "{e}");
    let e = error("[[traces]]\nmatch = \"*.mcap\"\nstrikt = true\n");
    assert!(
        e.starts_with("suite/sweeptrace.toml:3:1: unknown key `strikt`"),
        "{e}"
    );
    let e = error("[[traces]]\nstrict = true\n");
    assert!(
        e.starts_with("suite/sweeptrace.toml:1:1: missing key `match`"),
        "{e}"
    );
}

#[test]
fn bad_values_name_file_line_and_what_is_allowed() {
    let e = error("\n[tolerances]\nalpha = -1e-5\n");
    assert_eq!(
        e,
        "suite/sweeptrace.toml:3:9: `tolerances.alpha` must be a finite number ≥ 0, got -0.00001"
    );
    let e = error("[tolerances]\ncontact = nan\n");
    assert!(
        e.starts_with("suite/sweeptrace.toml:2:11: `tolerances.contact` must be"),
        "{e}"
    );
    let e = error("fields = [\"kind\", \"colour\"]\n");
    assert_eq!(
        e,
        "suite/sweeptrace.toml:1:19: unknown field `colour` in `fields`; \
         the fields are kind, triangle, feature, alpha, normal, contact"
    );
    let e = error("fields = []\n");
    assert!(
        e.starts_with("suite/sweeptrace.toml:1:10: `fields` is empty"),
        "{e}"
    );
    let e = error("strict = \"yes\"\n");
    assert!(
        e.starts_with("suite/sweeptrace.toml:1:10: invalid type"),
        "{e}"
    );
    let e = error("[[traces]]\nmatch = \"a/[b\"\n");
    assert!(
        e.starts_with("suite/sweeptrace.toml:2:9: `match`: `a/[b` is not a glob"),
        "{e}"
    );
    let e = error("strict = \n");
    assert!(e.starts_with("suite/sweeptrace.toml:1:"), "{e}");
}

#[test]
fn print_config_names_every_source() {
    let f = parse("[tolerances]\nalpha = 1e-5\n", "ex/sweeptrace.toml");
    let cli = Overrides {
        strict: Some(true),
        ..Overrides::default()
    };
    let s = resolve(&[f], Path::new("ex/t.mcap"), &cli);
    let text = render_settings_text(&[("ex/t.mcap".to_string(), s.clone())]);
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 7, "{text}");
    assert_eq!(lines[0], "ex/t.mcap");
    let expect = [
        ("tolerances.alpha = 1e-5", "# ex/sweeptrace.toml:2"),
        ("tolerances.normal_degrees = 0.01", "# default"),
        ("tolerances.contact = 1e-6", "# default"),
        (
            "fields = [\"kind\", \"triangle\", \"feature\", \"alpha\", \"normal\", \"contact\"]",
            "# default",
        ),
        ("strict = true", "# command line"),
        ("allow_tunnels = false", "# default"),
    ];
    for (line, (setting, source)) in lines[1..].iter().zip(expect) {
        assert!(line.starts_with(&format!("  {setting} ")), "{text}");
        assert!(line.ends_with(source), "{text}");
    }
    // The sources start in one column.
    let columns: Vec<usize> = lines[1..].iter().filter_map(|l| l.find("  # ")).collect();
    assert!(
        columns.len() == 6 && columns.iter().all(|&c| c == columns[0]),
        "{text}"
    );
    let json: serde_json::Value =
        serde_json::from_str(&render_settings_json(&[("ex/t.mcap".to_string(), s)])).unwrap();
    let settings = &json["traces"][0]["settings"];
    assert_eq!(settings["tolerances.alpha"]["value"], 1e-5);
    assert_eq!(
        settings["tolerances.alpha"]["source"],
        serde_json::json!({"kind": "file", "file": "ex/sweeptrace.toml", "line": 2})
    );
    assert_eq!(settings["strict"]["source"]["kind"], "command_line");
    assert_eq!(settings["fields"]["source"]["kind"], "default");
}

#[test]
fn numbers_read_back() {
    for x in [1e-6, 1e-5, 0.01, 20.0, 0.5, 1.25e-7, 0.0] {
        let text = number_text(x);
        let back: f64 = text.parse().unwrap();
        assert_eq!(back, x, "{text}");
    }
    assert_eq!(number_text(1e-5), "1e-5");
    assert_eq!(number_text(0.01), "0.01");
    assert_eq!(number_text(20.0), "20.0");
}

#[test]
fn normalize_is_lexical() {
    assert_eq!(normalize(Path::new("a/./b/../c")), PathBuf::from("a/c"));
    assert_eq!(normalize(Path::new("../a")), PathBuf::from("../a"));
    assert_eq!(normalize(Path::new("/../a")), PathBuf::from("/a"));
}

#[test]
fn engine_sides_are_read_with_their_line_and_the_command_line_wins() {
    use crate::core::Sides;
    let f = parse(
        "[engine]\nprecision = \"f32\"\nsides = \"two\"\n",
        "e/sweeptrace.toml",
    );
    let s = resolve(
        std::slice::from_ref(&f),
        Path::new("e/t.mcap"),
        &Overrides::default(),
    );
    assert_eq!(
        s.engine.sides,
        Some(Setting {
            value: Sides::Two,
            source: file("e/sweeptrace.toml", 3)
        })
    );
    assert_eq!(s.engine.conventions().sides, Sides::Two);
    // `--print-config` names the key and where it came from.
    let text = render_settings_text(&[("t.mcap".to_string(), s.clone())]);
    assert!(
        text.contains("engine.sides = \"two\"") && text.contains("e/sweeptrace.toml:3"),
        "{text}"
    );
    let json = render_settings_json(&[("t.mcap".to_string(), s)]);
    assert!(json.contains("\"engine.sides\""), "{json}");
    let command_line = Overrides {
        engine: PartialConventions {
            sides: Some(Setting {
                value: Sides::One,
                source: Source::CommandLine,
            }),
            ..PartialConventions::default()
        },
        ..Overrides::default()
    };
    let s = resolve(&[f], Path::new("e/t.mcap"), &command_line);
    assert_eq!(
        s.engine.sides.map(|s| (s.value, s.source)),
        Some((Sides::One, Source::CommandLine))
    );
}

#[test]
fn engine_sides_round_trip_through_the_table_inference_writes() {
    use crate::conventions::EngineConventions;
    use crate::core::Sides;
    let declared = EngineConventions {
        sides: Sides::Two,
        accuracy: Some("4096".parse().unwrap()),
        ..EngineConventions::default()
    };
    let table: String = std::iter::once("[engine]\n".to_string())
        .chain(
            declared
                .declared()
                .into_iter()
                .map(|(k, v)| format!("{k} = {v}\n")),
        )
        .collect();
    let f = parse(&table, "r/sweeptrace.toml");
    let s = resolve(&[f], Path::new("r/t.mcap"), &Overrides::default());
    assert_eq!(s.engine.conventions(), declared, "{table}");
}

#[test]
fn an_unknown_sides_value_names_the_closed_set() {
    let e = error("[engine]\nsides = \"both\"\n");
    assert!(
        e.contains("`engine.sides` is `both`; it takes one of \"one\", \"two\""),
        "{e}"
    );
    assert!(e.contains("sweeptrace.toml:2"), "{e}");
}
