//! The command line under hostile or unlucky input: machine files the model cannot hold (a
//! bearing 20 diameters long, 10,000 elements, bad station names, deep YAML) are refused with
//! the field and the reason, not a panic; a closed standard output ends a command quietly;
//! `replay` never writes into or over its input bag; errors are printed once.

mod common;

use common::run_cli;
use rotor_twin::rotor::MachineDescription;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("rotor-twin-guards-{name}-{}", std::process::id()));
    std::fs::remove_dir_all(&d).ok();
    d
}

fn shipped_machine() -> String {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("config/orc_microturbine_100kw.yaml");
    std::fs::read_to_string(p).unwrap()
}

/// The shipped machine with `from` replaced by `to` (once, checked).
fn machine_with(from: &str, to: &str) -> String {
    let text = shipped_machine();
    assert!(text.contains(from), "{from}");
    text.replacen(from, to, 1)
}

fn refusal(yaml: &str) -> String {
    MachineDescription::from_yaml(yaml, "m.yaml")
        .expect_err("must be refused")
        .to_string()
}

#[test]
fn machines_the_model_cannot_hold_are_refused_with_the_field() {
    // a bearing 20 diameters long (the film model's bound is 10)
    let long = machine_with("    length_m: 0.030\n", "    length_m: 1.2\n");
    let e = refusal(&long);
    assert!(
        e.contains("bearings[0].length_m = 1.2") && e.contains("10 diameters"),
        "{e}"
    );
    // 10,000 elements: 50 sections of 200
    let many = machine_with(
        "  - {length_m: 0.73333333, outer_diameter_m: 0.063, material: steel, elements: 22}\n",
        &"  - {length_m: 0.0146, outer_diameter_m: 0.063, material: steel, elements: 200}\n"
            .repeat(50),
    );
    let e = refusal(&many);
    assert!(
        e.contains("10") && e.contains("at most 200 elements"),
        "{e}"
    );
    // station names: empty, duplicate, 100 kB long (not echoed whole)
    let e = refusal(&machine_with("name: probe_outboard,", "name: '',"));
    assert!(e.contains("probes[1].name") && e.contains("empty"), "{e}");
    let e = refusal(&machine_with(
        "name: probe_outboard,",
        "name: probe_pulley_end,",
    ));
    assert!(e.contains("probes[1].name") && e.contains("unique"), "{e}");
    let huge = "x".repeat(100_000);
    let e = refusal(&machine_with(
        "name: probe_outboard,",
        &format!("name: {huge},"),
    ));
    assert!(
        e.contains("at most 64 characters") && e.len() < 300,
        "{} chars",
        e.len()
    );
    let e = refusal(&machine_with("name: bearing_outboard", "name: \"a\\tb\""));
    assert!(
        e.contains("bearings[1].name") && e.contains("control"),
        "{e}"
    );
}

/// 200 kB of nesting took minutes to parse before (issue 15): now refused at once.
#[test]
fn deep_yaml_is_refused_before_parsing() {
    let deep = format!("name: {}{}\n", "[".repeat(100_000), "]".repeat(100_000));
    let started = std::time::Instant::now();
    let e = refusal(&deep);
    assert!(e.contains("brackets open at once"), "{e}");
    let mut block = String::from("name: x\nmaterials:\n");
    for d in 1..400 {
        block += &format!("{}m{d}:\n", " ".repeat(d + 1));
    }
    let e = refusal(&block);
    assert!(e.contains("columns deep"), "{e}");
    // not a timing test: a bound far above the milliseconds this takes, to catch a parse
    assert!(started.elapsed().as_secs() < 5);
    let e = refusal(&"a: 1\n".repeat(300_000));
    assert!(e.contains("bytes"), "{e}");
}

/// The CLI with a machine the model cannot hold: an error (exit 1), not a panic (exit 101).
#[test]
fn a_long_bearing_fails_cleanly_in_the_cli() {
    let dir = scratch("long");
    std::fs::create_dir_all(&dir).unwrap();
    let cfg = dir.join("long.yaml");
    std::fs::write(
        &cfg,
        machine_with("    length_m: 0.030\n", "    length_m: 0.7\n"),
    )
    .unwrap();
    for cmd in [&["modes"][..], &["replay", "--no-bag"]] {
        let mut args = cmd.to_vec();
        args.extend(["--config", cfg.to_str().unwrap()]);
        let out = Command::new(env!("CARGO_BIN_EXE_rotor-twin"))
            .args(&args)
            .current_dir(&dir)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(
            err.contains("10 diameters") && !err.contains("panicked"),
            "{err}"
        );
    }
}

/// Runs the CLI with its standard output a pipe whose reader (`true`) has already exited: the
/// exit code and standard error.
fn with_closed_stdout(args: &[&str]) -> (Option<i32>, String) {
    let script = format!(
        "(sleep 0.3; \"$0\" {}; echo \"rc=$?\" >&2) | true",
        args.join(" ")
    );
    let out = Command::new("sh")
        .args(["-c", &script, env!("CARGO_BIN_EXE_rotor-twin")])
        .stderr(Stdio::piped())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    let code = err
        .lines()
        .find_map(|l| l.strip_prefix("rc="))
        .and_then(|c| c.parse().ok());
    (code, err)
}

/// A scratch directory holding a regular file, and the path `leaf` under that file: no
/// directory can be made there.
fn blocked_path(name: &str, leaf: &str) -> (PathBuf, PathBuf) {
    let dir = scratch(name);
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("a-file");
    std::fs::write(&file, "").unwrap();
    (dir.clone(), file.join(leaf))
}

/// `sweep` refuses a speed beyond the twin's limit and an output it cannot make before computing
/// any speed (issue 15, item 20): before, the progress bar ran through every speed first.
#[test]
fn sweep_checks_its_speeds_and_output_first() {
    let (dir, blocked) = blocked_path("sweep-first", "sweep");
    for (args, expect) in [
        // 100,000 rpm: above 10× the built-in machine's rated 9,000 rpm
        (
            vec!["--to-rpm", "100000", "--out", dir.to_str().unwrap()],
            "invalid --to-rpm 100000: above 90000 rpm",
        ),
        (
            vec!["--to-rpm", "4000", "--out", blocked.to_str().unwrap()],
            "--out: creating",
        ),
    ] {
        let out = Command::new(env!("CARGO_BIN_EXE_rotor-twin"))
            .args([
                "sweep",
                "--from-rpm",
                "3000",
                "--step-rpm",
                "1000",
                "--revs",
                "8",
            ])
            .args(["--model", "linear"])
            .args(&args)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains(expect), "{args:?}: {err}");
        assert!(!err.contains("sweep ["), "computed before refusing: {err}");
    }
}

/// `simulate` refuses a speed it cannot run with the reason, before computing (issue 15, item
/// 21: -100 said "unexpected argument", -inf was read as a flag, 1 rpm gave "invalid time step
/// 0.46875", a 300-digit speed ran into "equilibrium not found", its text twice).
#[test]
fn simulate_names_why_a_speed_cannot_run() {
    let huge = format!("1{}", "0".repeat(300));
    for (speed, expect) in [
        (
            "-100",
            "invalid speed -100 rpm: must be finite and above zero",
        ),
        (
            "-inf",
            "invalid speed -inf rpm: must be finite and above zero",
        ),
        // 128 steps a revolution of at most 0.1 s: 60 / 12.8 = 4.69 rpm
        ("1", "invalid speed 1 rpm: at or below 4.69 rpm"),
        ("4.6", "at or below 4.69 rpm"),
        (
            huge.as_str(),
            "invalid speed 1.000e300 rpm: above 90000 rpm",
        ),
    ] {
        let out = Command::new(env!("CARGO_BIN_EXE_rotor-twin"))
            .args(["simulate", "--revs", "2", "--speed-rpm", speed])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{speed}: {err}");
        assert!(err.contains(expect), "{speed}: {err}");
        assert!(err.len() < 300, "{speed}: {err}");
    }
}

/// A `--remap` or `--probe-point` naming a topic the bag does not have is an error naming it and
/// listing the bag's topics (issue 15, item 21: both were ignored, exit 0).
#[test]
fn replay_names_a_remap_or_probe_topic_the_bag_lacks() {
    let bag = Path::new(env!("CARGO_MANIFEST_DIR")).join("bags/orc_runup_synthetic");
    let out_dir = scratch("remap-missing");
    for (args, expect) in [
        (
            ["--remap", "/nope:=/rotor_twin/speed"],
            "the bag has no topic /nope (--remap",
        ),
        (
            ["--probe-point", "probe_outboard=/nope"],
            "the bag has no topic /nope (--probe-point",
        ),
    ] {
        let out = Command::new(env!("CARGO_BIN_EXE_rotor-twin"))
            .arg("replay")
            .arg(&bag)
            .args(["--no-bag", "--duration", "0.1", "--out"])
            .arg(&out_dir)
            .args(args)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(
            err.contains(expect) && err.contains("/rotor_twin/speed ["),
            "{args:?}: {err}"
        );
    }
}

/// Every command that prints ends quietly when its reader is gone (issue 15, item 16): no panic
/// (exit 101) and no error text; it ends as a Unix filter does, by SIGPIPE (the shell's 141), or
/// with 0 when it had written everything before the reader left.
#[test]
fn a_closed_stdout_ends_the_command_quietly() {
    let dir = scratch("pipe");
    std::fs::create_dir_all(&dir).unwrap();
    let bag = dir.join("synth");
    std::fs::remove_dir_all(&bag).ok();
    let bag_arg = format!("--out {} --ramp 0.2 --hold-end 0.1", bag.display());
    let sweep_out = format!("--out {}", dir.join("sweep").display());
    for args in [
        &["bearing"][..],
        &["bearing", "--json"],
        &["bench", "--seconds", "0.05"],
        &["modes"],
        &["response"],
        &[
            "simulate",
            "--speed-rpm",
            "3000",
            "--revs",
            "8",
            "--model",
            "linear",
        ],
        &[
            "sweep",
            "--from-rpm",
            "3000",
            "--to-rpm",
            "4000",
            "--step-rpm",
            "1000",
            "--revs",
            "8",
            "--model",
            "linear",
            &sweep_out,
        ],
        &["synth-bag", &bag_arg],
    ] {
        let (code, err) = with_closed_stdout(args);
        assert!(matches!(code, Some(0 | 141)), "{args:?}: {err}");
        assert!(
            !err.contains("panicked") && !err.contains("error"),
            "{args:?}: {err}"
        );
    }
}

#[test]
fn replay_never_writes_into_or_over_its_input() {
    let root = scratch("overlap");
    let bag = root.join("bag");
    std::fs::create_dir_all(&root).unwrap();
    let sample = Path::new(env!("CARGO_MANIFEST_DIR")).join("bags/orc_runup_synthetic");
    let status = Command::new("cp")
        .args(["-r", sample.to_str().unwrap(), bag.to_str().unwrap()])
        .status()
        .unwrap();
    assert!(status.success());
    // a previous replay's output there, so that only the overlap can refuse it
    std::fs::write(root.join("report.json"), "{}").unwrap();
    let before: Vec<_> = std::fs::read_dir(&bag)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    for out in [
        root.clone(),
        bag.clone(),
        bag.join("sub"),
        root.join("bag/../bag"),
    ] {
        let (ok, _, err) = run_cli(&[
            "replay",
            bag.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--duration",
            "0.01",
        ]);
        assert!(
            !ok && err.contains("input bag"),
            "--out {}: {err}",
            out.display()
        );
    }
    let after: Vec<_> = std::fs::read_dir(&bag)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert_eq!(before, after);
    assert!(rotor_twin::bag::Bag::read(&bag).unwrap().damage.is_empty());
}

#[test]
fn a_missing_bag_is_reported_once() {
    let (ok, out, err) = run_cli(&["replay", "/nonexistent/bag"]);
    assert!(!ok && out.is_empty());
    assert_eq!(err.matches("No such file").count(), 1, "{err}");
    assert_eq!(err.matches("/nonexistent/bag").count(), 1, "{err}");
    // refused before the film tables are built or loaded (a build can take minutes)
    assert!(!err.contains("film tables"), "{err}");
}

/// The files in a replay's output directory.
fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn replay_and_calibrate_reuse_their_output_directory() {
    let out = scratch("reuse");
    let out_s = out.to_str().unwrap();
    let plain = ["replay", "--out", out_s, "--duration", "0.05"];
    let calibrate = [
        "replay",
        "--out",
        out_s,
        "--duration",
        "0.6",
        "--calibrate",
        "--calibrate-window",
        "0:0.6",
    ];
    let (ok, _, err) = run_cli(&plain);
    assert!(ok, "{err}");
    assert!(listing(&out).contains(&"orbit_probe_outboard.svg".into()));
    std::fs::write(out.join("notes.txt"), "the user's").unwrap();
    // --calibrate over a replay's output, then again over its own (it writes no report.json)
    for run in 0..2 {
        let (ok, _, err) = run_cli(&calibrate);
        assert!(ok, "calibrate run {run}: {err}");
        // nothing of the earlier plain replay is left beside the calibration
        assert_eq!(
            listing(&out),
            ["bag", "calibration.json", "notes.txt"],
            "run {run}"
        );
    }
    // and a plain replay over a calibration leaves no stale calibration.json
    let (ok, _, err) = run_cli(&plain);
    assert!(ok, "{err}");
    let names = listing(&out);
    assert!(
        names.contains(&"report.json".into()) && !names.contains(&"calibration.json".into()),
        "{names:?}"
    );
    assert!(names.contains(&"notes.txt".into()), "{names:?}");
    std::fs::remove_dir_all(&out).ok();
}

/// An empty `--out` directory (as a failed run leaves one) is used as it is; a directory with
/// a file of the user's and no earlier replay's output is refused, and the file is kept.
#[test]
fn an_empty_output_directory_is_used_and_a_foreign_one_refused() {
    let out = scratch("empty-out");
    std::fs::create_dir_all(&out).unwrap();
    let out_s = out.to_str().unwrap();
    let (ok, _, err) = run_cli(&["replay", "--out", out_s, "--duration", "0.05"]);
    assert!(ok, "{err}");
    assert!(listing(&out).contains(&"report.json".into()));
    let foreign = scratch("foreign-out");
    std::fs::create_dir_all(&foreign).unwrap();
    std::fs::write(foreign.join("notes.txt"), "the user's").unwrap();
    let (ok, _, err) = run_cli(&[
        "replay",
        "--out",
        foreign.to_str().unwrap(),
        "--duration",
        "0.05",
    ]);
    assert!(!ok);
    assert!(err.contains("is not a previous replay's output"), "{err}");
    assert_eq!(listing(&foreign), ["notes.txt"]);
    std::fs::remove_dir_all(&out).ok();
    std::fs::remove_dir_all(&foreign).ok();
}

/// A bag of `speeds_rpm` as /rotor_twin/speed, 10 ms apart (an empty list: the topic without a
/// message).
fn speed_bag(name: &str, speeds_rpm: &[f64]) -> PathBuf {
    use rotor_twin::messages::{Header, RotorSpeed, Time};
    let dir = scratch(name);
    let mut rec = rotor_twin::record::Recorder::create(&dir).unwrap();
    let h = rec
        .add_topic::<RotorSpeed>(
            rotor_twin::topics::SPEED,
            rotor_twin::topics::INPUT_RECORDED,
        )
        .unwrap();
    for (i, rpm) in speeds_rpm.iter().enumerate() {
        let ns = 1_700_000_000_000_000_000 + i as u64 * 10_000_000;
        let m = RotorSpeed {
            header: Header {
                stamp: Time::from_nanos(ns as i64),
                frame_id: String::new(),
            },
            speed: rpm * std::f64::consts::PI / 30.0,
            acceleration: 0.0,
        };
        rec.write(h, &m, ns, ns).unwrap();
    }
    rec.finish().unwrap()
}

/// A replay in which the twin never starts (an empty bag; speeds all below the minimum speed,
/// 1,000 rpm; speeds all refused) is an error that says why (issue 15, item 21: it exited 0
/// with no note); the report is still written.
#[test]
fn a_replay_that_never_starts_the_twin_fails_and_says_why() {
    let cases: [(&str, Vec<f64>, &[&str]); 3] = [
        ("empty", vec![], &["no message to replay"]),
        (
            "slow",
            vec![500.0; 100],
            &["of its 100 message(s)", "1000 rpm"],
        ),
        (
            "refused",
            vec![f64::NAN; 20],
            &["20 refused on /rotor_twin/speed"],
        ),
    ];
    for (name, speeds, expect) in cases {
        let bag = speed_bag(&format!("never-{name}"), &speeds);
        let out = scratch(&format!("never-{name}-out"));
        let (ok, _, err) = run_cli(&[
            "replay",
            bag.to_str().unwrap(),
            "--no-bag",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(!ok, "{name}: exit 0");
        assert!(err.contains("the twin never started"), "{name}: {err}");
        for e in expect {
            assert!(err.contains(e), "{name}: '{e}' not in {err}");
        }
        assert!(out.join("report.json").is_file(), "{name}");
    }
}

/// Runs the CLI; asserts exit 1 (a refusal, not a panic and not a success) and an error of at
/// most 300 characters that contains `expect` once, with no "-i"-style flag reading; returns it.
fn refused(args: &[&str], expect: &str) -> String {
    let (ok, _out, err) = run_cli(args);
    assert!(!ok, "{args:?} succeeded: {err}");
    assert!(!err.contains("panicked"), "{args:?}: {err}");
    assert!(err.contains(expect), "{args:?}: {err}");
    assert_eq!(err.matches(expect).count(), 1, "{args:?} twice: {err}");
    assert!(err.len() < 300, "{args:?}: {} characters: {err}", err.len());
    assert!(!err.contains("unexpected argument"), "{args:?}: {err}");
    err
}

/// A negative number, `-inf` among them, is the value of the option before it in every
/// subcommand, and meets that option's own check (issue 15, item 21: `-inf` was read as the
/// flags `-i -n -f` in `bearing`, `modes`, `response` and `simulate --revs`).
#[test]
fn negative_numbers_are_values_in_every_subcommand() {
    for (args, expect) in [
        (
            &["bearing", "--speed-rpm", "-inf"][..],
            "invalid --speed-rpm -inf",
        ),
        (&["bearing", "--speed-rpm", "-5"], "invalid --speed-rpm -5"),
        (&["modes", "--from-rpm", "-inf"], "invalid --from-rpm -inf"),
        (&["modes", "--to-rpm", "-inf"], "invalid --to-rpm -inf"),
        (&["response", "--to-rpm", "-inf"], "invalid --to-rpm -inf"),
        (
            &["response", "--step-rpm", "-inf"],
            "invalid --step-rpm -inf",
        ),
        (
            &["simulate", "--speed-rpm", "3000", "--revs", "-inf"],
            "invalid value '-inf' for '--revs",
        ),
        (
            &["simulate", "--speed-rpm", "3000", "--revs", "-5"],
            "invalid value '-5' for '--revs",
        ),
        (
            &["simulate", "--speed-rpm", "-inf", "--revs", "2"],
            "invalid speed -inf rpm",
        ),
        (
            &[
                "sweep",
                "--from-rpm",
                "-inf",
                "--to-rpm",
                "4000",
                "--step-rpm",
                "500",
            ],
            "invalid --from-rpm -inf",
        ),
        (
            &[
                "simulate",
                "--revs",
                "2",
                "--speed-rpm",
                "3000",
                "--kick",
                "-0.5:3:1:0",
            ],
            "invalid --kick \"-0.5:3:1:0\": T = -0.5 s must be at least 0",
        ),
    ] {
        refused(args, expect);
    }
}

/// `bearing --speed-rpm` is checked before the equilibrium is sought, the error naming the
/// field, the value as given (rpm) and the valid range (issue 15, item 21: -5, 1 and 1e30 rpm
/// said "static equilibrium not found"; `--speed-rpm=-inf` was reported in rad/s).
#[test]
fn bearing_names_a_speed_out_of_its_range() {
    // Ø 60 mm: 500 m/s of surface speed is 500 / (π · 0.06) · 60 = 159,155 rpm
    for speed in ["--speed-rpm=-inf", "--speed-rpm=-5", "--speed-rpm=1e30"] {
        let err = refused(&["bearing", speed], "must lie in (0, 159154] rpm");
        let given = speed.trim_start_matches("--speed-rpm=");
        let shown = if given == "1e30" { "1.000e30" } else { given };
        assert!(
            err.contains(&format!("invalid --speed-rpm {shown}:")),
            "{err}"
        );
        assert!(
            !err.contains("rad/s") && !err.contains("equilibrium"),
            "{err}"
        );
    }
    // 1 rpm cannot carry 275 N: the lowest speed that can is named, and it is right: the finite
    // film's force is proportional to the speed (laminar, isoviscous: Reynolds' equation is
    // linear in ω), so 10 % above that speed the equilibrium is found at an ε just below the
    // bound, and at 0.9 of it the same refusal comes back.
    let err = refused(
        &["bearing", "--speed-rpm", "1"],
        "too slow for the load of 275 N",
    );
    let lowest: f64 = err
        .split("lowest speed that carries it is about ")
        .nth(1)
        .and_then(|t| t.split(' ').next())
        .and_then(|t| t.parse().ok())
        .unwrap_or_else(|| panic!("{err}"));
    // 1 rpm: 11.79 N at ε 0.994, so 275 / 11.79 = 23.3 rpm
    assert!((lowest - 23.4).abs() < 0.15, "{err}");
    // just above it the equilibrium lies near the bound (at 24 rpm Newton's method still fails)
    let above = 1.1 * lowest;
    let (ok, out, err) = run_cli(&["bearing", "--speed-rpm", &above.to_string(), "--json"]);
    assert!(ok, "{above} rpm: {err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let eps = v["eccentricity_ratio"].as_f64().unwrap();
    assert!(eps > 0.98 && eps < 0.994, "ε {eps} at {above} rpm");
    refused(
        &["bearing", "--speed-rpm", &(0.9 * lowest).to_string()],
        "too slow for the load of 275 N",
    );
}

/// `bearing --speeds` ends at the journal's surface speed limit as `--speed-rpm` does (500 m/s:
/// 159,155 rpm for the flags' Ø 60 mm; the machine file's journal, also Ø 60 mm, the same),
/// refused before any equilibrium is sought, the error naming the field, the value and the
/// bound (before session 10 a sweep to 1e9 rpm ran, "static equilibrium ... not found" or a
/// table of nonsense). A range ending at the bound still runs.
#[test]
fn bearing_speeds_end_at_the_surface_speed_limit() {
    let machine = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/config/orc_microturbine_100kw.yaml"
    );
    for extra in [&[][..], &["--config", machine][..]] {
        for (range, shown) in [
            ("1000:200000:50000", "200000"),
            ("1000:1e12:5e11", "1.000e12"),
        ] {
            let mut args = vec!["bearing", "--speeds", range];
            args.extend_from_slice(extra);
            let err = refused(
                &args,
                &format!("invalid --speeds: {shown} rpm is above 159154 rpm"),
            );
            assert!(err.contains("500 m/s") && err.contains("0.06 m"), "{err}");
            assert!(!err.contains("equilibrium"), "{err}");
        }
    }
    let (ok, out, err) = run_cli(&["bearing", "--speeds", "100000:150000:50000", "--json"]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["speeds"].as_array().map(Vec::len), Some(2), "{v}");
}

/// Numbers in errors are shown in a bounded format, never 300 digits (issue 15, item 21).
#[test]
fn huge_numbers_are_not_echoed_whole() {
    refused(
        &["modes", "--from-rpm", "1e300"],
        "invalid --from-rpm 1.000e300",
    );
    refused(
        &["response", "--to-rpm", "1e300"],
        "invalid --to-rpm 1.000e300",
    );
    let e = refusal(&machine_with(
        "gravity_m_s2: [0.0, -9.81]",
        "gravity_m_s2: [0.0, -1e300]",
    ));
    assert!(
        e.contains("gravity_m_s2[1] = -1.000e300") && e.len() < 300,
        "{e}"
    );
}

/// `rated_speed_rpm` is bounded by the shaft's surface speed (issue 15, item 21: 1e9 rpm was
/// accepted and `simulate` at 5e8 rpm reported "stable").
#[test]
fn a_rated_speed_no_shaft_survives_is_refused() {
    // the shipped machine's largest shaft diameter is its Ø63 mm body (reading (B), the default
    // since session 15): 500 m/s is 500 / (π · 0.063 m) · 60 = 151,576 rpm
    let e = refusal(&machine_with(
        "rated_speed_rpm: 9000",
        "rated_speed_rpm: 1e9",
    ));
    assert!(
        e.contains("rated_speed_rpm = 1000000000")
            && e.contains("at most 151576 rpm")
            && e.contains("0.063 m"),
        "{e}"
    );
    MachineDescription::from_yaml(
        &machine_with("rated_speed_rpm: 9000", "rated_speed_rpm: 150000"),
        "m.yaml",
    )
    .expect("150,000 rpm: 495 m/s on Ø 63 mm");
}

/// Each field of `--kick` and `--speed-history` is checked before the run, the error naming it
/// (issue 15, item 21: an impulse of 1e300 N·s and a speed of 1e300 rpm gave unrelated errors).
#[test]
fn kick_and_speed_history_fields_are_named() {
    let base = ["simulate", "--revs", "2"];
    for (extra, expect) in [
        (
            &["--speed-rpm", "3000", "--kick", "0.01:15:1e300:0"][..],
            "invalid --kick \"0.01:15:1e300:0\": JX = 1.000e300 N·s must be at most",
        ),
        (
            &["--speed-rpm", "3000", "--kick", "0.01:99:1:0"],
            "NODE = 99 must be a shaft node, 0 to 30",
        ),
        (
            &["--speed-history", "0:8000,1:1e300"],
            "invalid --speed-history \"1:1e300\": RPM = 1.000e300 rpm: above 90000 rpm",
        ),
        (
            &["--ramp", "3000:1e300:100"],
            "invalid --ramp \"3000:1e300:100\": TO = 1.000e300 rpm: above 90000 rpm",
        ),
    ] {
        let args: Vec<&str> = base.iter().chain(extra).copied().collect();
        refused(&args, expect);
    }
}

/// Output paths are checked before anything is computed, missing directories made, and an
/// error reported once (issue 15, items 20 and 21: `simulate --plot`, `--history-csv`, `modes
/// --plot` and `response --plot` failed only after the computation, the text doubled).
#[test]
fn outputs_are_checked_before_computing() {
    let (dir, blocked) = blocked_path("outputs", "out");
    let b = blocked.to_str().unwrap();
    let simulate = |option| vec!["simulate", "--speed-rpm", "3000", "--revs", "2", option, b];
    for (args, expect) in [
        (simulate("--plot"), "--plot: creating"),
        (
            simulate("--history-csv"),
            "--history-csv: cannot write into",
        ),
        (vec!["modes", "--plot", b], "--plot: cannot write into"),
        (
            vec!["modes", "--shapes-rpm", "9000", "--shapes-plot", b],
            "--shapes-plot: cannot write into",
        ),
        (vec!["response", "--plot", b], "--plot: cannot write into"),
    ] {
        let err = refused(&args, expect);
        assert!(
            !err.contains("backend") && !err.contains("film tables"),
            "{err}"
        );
    }
    // a missing directory is made, as `sweep --out` does
    let deep = dir.join("new/deeper/campbell.svg");
    let (ok, _, err) = run_cli(&["modes", "--plot", deep.to_str().unwrap()]);
    assert!(ok && deep.exists(), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// The one format of numbers in errors: as written when short, else four significant digits.
#[test]
fn long_numbers_are_shown_in_scientific_notation() {
    use rotor_twin::units::shown_value;
    assert_eq!(shown_value(9000.0), "9000");
    assert_eq!(shown_value(-5.0), "-5");
    assert_eq!(shown_value(f64::NEG_INFINITY), "-inf");
    assert_eq!(shown_value(1e300), "1.000e300");
    assert_eq!(shown_value(-1.23456e-7), "-1.235e-7");
    assert_eq!(shown_value(0.1 + 0.2), "3.000e-1");
}

/// `bearing --thermal` takes the built-in machine's MDM viscosity table by default (session 14),
/// valid 10–120 °C: a supply temperature outside it is refused naming the flag, the value and
/// the law's range (the Walther default before accepted 0–250 °C and read 130 °C off a law
/// extrapolated past its points); inside it the thermal film runs and its peak lies above the
/// supply (the seed bearing at 9,000 rpm: 47.9 °C for 40 °C, README "The seed bearing").
#[test]
fn thermal_supply_outside_the_oil_law_is_refused() {
    let (ok, _, err) = run_cli(&["bearing", "--thermal", "--supply-temperature-c", "130"]);
    assert!(!ok);
    assert!(err.contains("--supply-temperature-c 130"), "{err}");
    assert!(err.contains("10–120 °C"), "{err}");
    let (ok, out, err) = run_cli(&["bearing", "--thermal", "--speed-rpm", "9000", "--json"]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let peak = v["thermal"]["max_temperature_c"].as_f64().unwrap();
    assert!((peak - 47.907).abs() < 0.05, "peak {peak} °C");
}
