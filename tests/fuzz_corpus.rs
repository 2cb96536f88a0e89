//! The fuzz targets' checks on stable (`sweeptrace::fuzzing`, the same
//! functions the `cargo fuzz` targets in `fuzz/` call): every file of the
//! committed, minimized corpus (`fuzz/corpus/TARGET/`), a seeded loop of
//! generated inputs, and one named test per finding of the fuzzer
//! (FUZZING.md), whose input is kept under `tests/fixtures/fuzz/`.

use std::path::{Path, PathBuf};

use libtest_mimic::Trial;
use rand::{Rng, RngCore, SeedableRng};
use rand_chacha::ChaCha8Rng;
use sweeptrace::fuzzing::{check_core, check_message_validation, check_trace_reader};
use sweeptrace::trace::validate::validate_sweep;
use sweeptrace::trace::{SweepMsg, TraceError, TraceReader};

use crate::{ensure, trial};
use anyhow::Context as _;

type Check = fn(&[u8]) -> Result<(), String>;

/// The fuzz targets and the checks they run.
const TARGETS: [(&str, Check); 3] = [
    ("trace_reader", check_trace_reader),
    ("message_json", check_message_validation),
    ("core_numbers", check_core),
];

pub fn tests() -> Vec<Trial> {
    let mut trials = vec![
        trial!(header_declaring_a_4_gib_string_is_refused),
        trial!(summary_declaring_a_4_gib_string_is_read_in_file_order),
        trial!(metadata_map_whose_last_length_lies_past_its_end_is_refused),
        trial!(sweep_whose_path_length_overflows_is_refused),
        trial!(unknown_field_is_named_once),
        trial!(seeded_core_numbers),
        trial!(seeded_message_json),
        trial!(seeded_trace_reader),
    ];
    for (target, check) in TARGETS {
        let name = format!("fuzz_corpus::corpus::{target}");
        trials.push(crate::trial(&name, move || run_corpus(target, check)));
    }
    trials
}

fn fixture(name: &str) -> anyhow::Result<Vec<u8>> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/fuzz")
        .join(name);
    std::fs::read(&path).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))
}

/// Runs `check` on `input`, a panic included, naming the input on failure.
fn run_one(check: Check, input: &[u8], what: &str) -> anyhow::Result<()> {
    match std::panic::catch_unwind(|| check(input)) {
        Ok(Ok(())) => Ok(()),
        Ok(Err(broken)) => Err(anyhow::anyhow!("{what}: {broken}")),
        Err(_) => Err(anyhow::anyhow!("{what}: panicked on {input:02x?}")),
    }
}

/// Every file of `fuzz/corpus/TARGET/`; the corpus must not be empty.
fn run_corpus(target: &str, check: Check) -> anyhow::Result<()> {
    let dir: PathBuf = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fuzz/corpus")
        .join(target);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .map_err(|e| anyhow::anyhow!("{}: {e}", dir.display()))?
        .filter_map(Result::ok)
        .map(|e| e.path())
        .collect();
    files.sort();
    ensure!(!files.is_empty(), "{} holds no corpus", dir.display());
    for file in files {
        let input = std::fs::read(&file)?;
        run_one(check, &input, &file.display().to_string())?;
    }
    Ok(())
}

/// The fuzzer's first find: a header record of a few bytes whose profile
/// string declares 0xfdffffff bytes made the `mcap` crate reserve 4 GiB.
/// The reader now refuses it before parsing, naming the file.
fn header_declaring_a_4_gib_string_is_refused() -> anyhow::Result<()> {
    let input = fixture("header_declares_4_gib_string.mcap")?;
    run_one(check_trace_reader, &input, "the fuzzer's input")?;
    let error = TraceReader::new(input.as_slice(), "found.mcap")
        .find_map(Result::err)
        .context("no error")?;
    ensure!(
        matches!(
            error,
            TraceError::FieldTooLong {
                declared: 0xfdff_ffff,
                ..
            }
        ) && error.to_string().starts_with("found.mcap: "),
        "{error:?}"
    );
    Ok(())
}

/// The third find: a metadata record whose string map ends inside an
/// entry's length; the crate read that length from the bytes after the
/// map (2.3 GB asked for). Lengths must now lie inside their map.
fn metadata_map_whose_last_length_lies_past_its_end_is_refused() -> anyhow::Result<()> {
    let input = fixture("metadata_map_length_past_its_end.mcap")?;
    run_one(check_trace_reader, &input, "the fuzzer's input")?;
    let error = TraceReader::new(input.as_slice(), "found.mcap")
        .find_map(Result::err)
        .context("no error")?;
    ensure!(
        matches!(error, TraceError::FieldTooLong { .. }),
        "{error:?}"
    );
    Ok(())
}

/// The same through the summary (a channel record of the summary section
/// declaring a 4 GiB string), found once the reader looked at the summary
/// for chunk indexes: the summary is now read with the same length checks,
/// and a summary that fails them is ignored (the file is read in file
/// order, which reports what is wrong with it).
fn summary_declaring_a_4_gib_string_is_read_in_file_order() -> anyhow::Result<()> {
    let input = fixture("summary_channel_declares_4_gib_string.mcap")?;
    run_one(check_trace_reader, &input, "the fuzzer's input")?;
    let mut reader = TraceReader::new_indexed(std::io::Cursor::new(&input), "found.mcap");
    reader.by_ref().for_each(drop);
    ensure!(
        !reader.stats().read_through_chunk_indexes,
        "the corrupt summary was used"
    );
    Ok(())
}

/// A sweep whose ends are finite but so far apart that the path's length
/// overflows (`p0` at z = 1e300) passed the trace validation and was then
/// refused by the core: the validation now refuses it, on `p1`.
fn sweep_whose_path_length_overflows_is_refused() -> anyhow::Result<()> {
    let input = fixture("sweep_path_length_overflows.json")?;
    run_one(check_message_validation, &input, "the fuzzer's input")?;
    let sweep: SweepMsg = serde_json::from_slice(&input)?;
    match validate_sweep(&sweep, Some(0.0)) {
        Err(problem) if problem.field == "p1" && problem.problem.contains("overflows") => Ok(()),
        other => Err(anyhow::anyhow!("validated as {other:?}")),
    }
}

/// The fuzzer's message check found the name of an unknown field said
/// twice (`field `x`: unknown field `x`, expected one of ...`): the field
/// is now named once.
fn unknown_field_is_named_once() -> anyhow::Result<()> {
    let input = br#"{"frame":0,"radius":0.5,"p0":[0,0,0],"p1":[0,0,1],"speed":2}"#;
    run_one(check_message_validation, input, "the message")?;
    let at = sweeptrace::trace::MessageAt {
        file: "found.mcap".to_string(),
        channel: "/sweep".to_string(),
        index: 3,
        frame: None,
    };
    let error = sweeptrace::trace::validate::parse_message::<SweepMsg>(input, at)
        .err()
        .context("the message was accepted")?
        .to_string();
    ensure!(
        error.matches("speed").count() == 1
            && error.contains("field `speed`: not a field of this message; expected one of"),
        "{error}"
    );
    Ok(())
}

/// Generated inputs for the core: random bytes, decoded by the same
/// `Numbers` as the fuzz target (small dyadic values, specials, raw bits).
fn seeded_core_numbers() -> anyhow::Result<()> {
    let mut rng = ChaCha8Rng::seed_from_u64(14);
    for case in 0..5_000 {
        let mut input = vec![0u8; rng.random_range(0..160)];
        rng.fill_bytes(&mut input);
        run_one(check_core, &input, &format!("case {case}"))?;
    }
    Ok(())
}

/// Generated messages: each of the three messages with numbers drawn from
/// ordinary, huge, tiny and out-of-range values, and fields left out.
fn seeded_message_json() -> anyhow::Result<()> {
    const NUMBERS: [&str; 12] = [
        "0",
        "-0.0",
        "0.5",
        "-2",
        "1e300",
        "-1e300",
        "1.7976931348623157e308",
        "5e-324",
        "1e400",
        "null",
        "3",
        "\"x\"",
    ];
    let mut rng = ChaCha8Rng::seed_from_u64(14);
    let mut number = |rng: &mut ChaCha8Rng| NUMBERS[rng.random_range(0..NUMBERS.len())];
    for case in 0..5_000 {
        let point = |rng: &mut ChaCha8Rng,
                     number: &mut dyn FnMut(&mut ChaCha8Rng) -> &'static str| {
            format!("[{},{},{}]", number(rng), number(rng), number(rng))
        };
        let input = match case % 5 {
            // Contact queries and an engine's contacts (issue 45).
            3 => format!(
                r#"{{"frame":2,"radius":{},"centre":{},"distance":{}}}"#,
                number(&mut rng),
                point(&mut rng, &mut number),
                number(&mut rng)
            ),
            4 => format!(
                r#"{{"frame":2,"contacts":[{{"triangle":{},"kind":"vertex","feature":{},"normal":{},"separation":{}}}]}}"#,
                rng.random_range(0..3),
                rng.random_range(0..5),
                point(&mut rng, &mut number),
                number(&mut rng)
            ),
            0 => format!(
                r#"{{"vertices":[{},{},{}],"triangles":[[0,1,{}]],"margin":{}}}"#,
                point(&mut rng, &mut number),
                point(&mut rng, &mut number),
                point(&mut rng, &mut number),
                rng.random_range(0..4),
                number(&mut rng)
            ),
            1 => format!(
                r#"{{"frame":{},"radius":{},"p0":{},"p1":{}}}"#,
                rng.random_range(0..3),
                number(&mut rng),
                point(&mut rng, &mut number),
                point(&mut rng, &mut number)
            ),
            _ => format!(
                r#"{{"frame":1,"alpha":{},"kind":"edge","feature":{},"normal":{}}}"#,
                number(&mut rng),
                rng.random_range(0..5),
                point(&mut rng, &mut number)
            ),
        };
        run_one(check_message_validation, input.as_bytes(), &input)?;
    }
    Ok(())
}

/// Generated traces: the small fixtures with a few bytes changed.
fn seeded_trace_reader() -> anyhow::Result<()> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures");
    let mut originals = Vec::new();
    for name in ["tunnel_floor.mcap", "python_written.mcap"] {
        originals.push(std::fs::read(dir.join(name))?);
    }
    let mut rng = ChaCha8Rng::seed_from_u64(14);
    for case in 0..300 {
        let mut input = originals[case % originals.len()].clone();
        for _ in 0..rng.random_range(1..4) {
            let at = rng.random_range(0..input.len());
            input[at] = rng.random();
        }
        if rng.random_bool(0.2) {
            input.truncate(rng.random_range(0..input.len()));
        }
        run_one(check_trace_reader, &input, &format!("case {case}"))?;
    }
    Ok(())
}
