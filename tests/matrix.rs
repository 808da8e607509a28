//! The feature matrix (`testkit::matrix`): mixes drawn across every
//! dimension of the mix format, each held to one end-to-end property.
//! Either the audit refuses the mix with its reason, or: the Verilog is
//! emitted; the model, rust-hdl and Verilator (and Icarus in the wide
//! draw) pass against the model under a scene that switches modes; the
//! Verilator run's waveform passes `check --no-model`, a window from its
//! middle passes `check`; `decode` of the link's bytes gives the samples
//! `--samples` wrote; `faults` judges the mix's own clean run clean; and in
//! the wide draw `prove` proves, or says what it left out.
//!
//! A quick draw (the first points of the pairwise cover) runs in `make
//! test`; the whole cover and free draws in `make test-long`.

use std::path::Path;
use std::process::{Command, Output};

use testkit::matrix::{self, Modes, Point};

fn slotforge(args: &[&dyn AsRef<std::ffi::OsStr>]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_slotforge"))
        .args(args.iter().map(|a| a.as_ref()))
        .output()
        .unwrap()
}

/// What went wrong with one mix, each step's failure with its output.
struct Faults(Vec<String>);

impl Faults {
    /// Runs `args`; a non-zero exit is a failure named `what`.
    fn run(&mut self, what: &str, args: &[&dyn AsRef<std::ffi::OsStr>]) -> Option<Output> {
        let out = slotforge(args);
        if out.status.success() {
            return Some(out);
        }
        let text = String::from_utf8_lossy(&out.stdout).to_string()
            + &String::from_utf8_lossy(&out.stderr);
        let tail: Vec<&str> = text.lines().rev().take(8).collect();
        let tail: Vec<&str> = tail.into_iter().rev().collect();
        self.0.push(format!(
            "{what} (exit {:?}):\n    {}",
            out.status.code(),
            tail.join("\n    ")
        ));
        None
    }
}

/// The scene that switches a mode mix: pin requests of `busy` then `rest`,
/// or a touch of the watched channel; nothing for a mix without modes.
fn scene(p: &Point) -> Vec<String> {
    match p.modes {
        Modes::None => vec![],
        Modes::Pin => vec!["--modes".into(), "1=busy,4=rest".into()],
        Modes::Auto => vec!["--stimulus".into(), "touch:A0@1-3".into()],
    }
}

const FRAMES: &str = "8";

/// The rows of a samples or decode CSV as (channel, sampled_s, value), in
/// file order, and each row's `cycle` where the file has one.
fn rows(path: &Path) -> (Vec<(String, String, String)>, Vec<u64>) {
    let text = std::fs::read_to_string(path).unwrap_or_default();
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
    let col = |n: &str| head.iter().position(|h| *h == n);
    let (Some(c), Some(t), Some(v)) = (col("channel"), col("sampled_s"), col("value")) else {
        return (vec![], vec![]);
    };
    let f: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    let cycles = col("cycle").map_or(vec![], |k| {
        f.iter().filter_map(|f| f[k].parse().ok()).collect()
    });
    let out = (f.iter())
        .map(|f| (f[c].to_string(), f[t].to_string(), f[v].to_string()))
        .collect();
    (out, cycles)
}

/// `decode` of the link's bytes against `--samples`: the decoded rows are
/// the run's first rows, and every row not decoded was strobed in the
/// run's last two slices (in flight when it ended).
fn decoded_as_sampled(p: &Point, csv: &Path, dec: &Path) -> Option<String> {
    let ((s, cycles), (got, _)) = (rows(csv), rows(dec));
    let slice = p.clock_mhz * 1_000;
    let late = FRAMES.parse::<u64>().unwrap() * 2 * slice - 2 * slice;
    let prefix = !got.is_empty() && got.len() <= s.len() && got[..] == s[..got.len()];
    let tail =
        cycles.len() == s.len() && cycles[got.len().min(s.len())..].iter().all(|&c| c >= late);
    (!prefix || !tail).then(|| {
        format!(
            "decode of --link-bytes: {} rows, --samples: {} rows (the rest must be in flight); first differing: {:?}",
            got.len(),
            s.len(),
            s.iter().zip(&got).find(|(a, b)| a != b)
        )
    })
}

/// What the error of each crossing docs/mix-format.md ("Combinations
/// refused") lists says: the phrase after "the error says".
fn refused_crossings() -> Vec<String> {
    let doc =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/mix-format.md"))
            .unwrap();
    let section = doc.split("## Combinations refused").nth(1).unwrap();
    let section = section.split("\n## ").next().unwrap();
    let said: Vec<String> = section
        .split("the error says `")
        .skip(1)
        .filter_map(|s| s.split('`').next().map(str::to_string))
        .collect();
    assert!(said.len() >= 4, "{said:?}");
    said
}

/// One mix through every feature; `wide`: also Icarus and `prove`.
/// `Ok(false)` when the audit refused it (with a reason), `Err` with every
/// failure otherwise.
fn through(p: &Point, seed: u64, wide: bool) -> Result<bool, String> {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let text = matrix::mix(p, seed);
    let mix = d.join(format!("matrix-{seed}.toml"));
    std::fs::write(&mix, &text).unwrap();
    let mut f = Faults(vec![]);
    let audit = slotforge(&[&"audit", &mix]);
    if !audit.status.success() {
        let why = String::from_utf8_lossy(&audit.stderr).to_string()
            + &String::from_utf8_lossy(&audit.stdout);
        // a refusal is a crossing docs/mix-format.md lists as refused, said
        // in its words; or a mix that does not fit, with the audit's reasons
        let listed = refused_crossings().iter().any(|r| why.contains(r.as_str()));
        let infeasible = audit.status.code() == Some(1) && why.contains("no jitter-free schedule");
        return match (audit.status.code(), listed || infeasible) {
            (Some(1 | 2), true) => Ok(false),
            _ => Err(format!(
                "{p:?}: audit exit {:?}, not a refusal docs/mix-format.md lists:\n{why}\n{text}",
                audit.status.code()
            )),
        };
    }
    let sc = scene(p);
    let sc: Vec<&dyn AsRef<std::ffi::OsStr>> = sc.iter().map(|s| s as _).collect();
    f.run("verilog", &[&"verilog", &mix, &"-o", &d.join("v")]);
    let mut engines = vec!["model", "rusthdl"];
    if wide {
        engines.push("icarus");
    }
    for e in engines {
        let mut a: Vec<&dyn AsRef<std::ffi::OsStr>> =
            vec![&"sim", &mix, &"--quiet", &"--frames", &FRAMES, &"--backend"];
        a.push(&e);
        a.extend(sc.iter().copied());
        f.run(&format!("sim --backend {e}"), &a);
    }
    // Verilator: the whole run's waveform, its samples and link bytes
    let (vcd, csv, bytes) = (d.join("run.vcd"), d.join("s.csv"), d.join("l.bin"));
    let mut out: Vec<&dyn AsRef<std::ffi::OsStr>> = vec![&"--samples", &csv];
    if p.link != matrix::Link::None {
        out.extend([&"--link-bytes" as &dyn AsRef<std::ffi::OsStr>, &bytes]);
    }
    if verilator(&mut f, &mix, &sc, ("0", FRAMES, &vcd), &out) {
        f.run(
            "check --no-model of the run",
            &[&"check", &mix, &vcd, &"--no-model", &"--quiet"],
        );
        f.run("check of the run", &[&"check", &mix, &vcd, &"--quiet"]);
    }
    let win = d.join("win.vcd");
    if verilator(&mut f, &mix, &sc, ("3", "6", &win), &[]) {
        f.run(
            "check of a window from the middle",
            &[&"check", &mix, &win, &"--quiet"],
        );
    }
    if p.link != matrix::Link::None && bytes.exists() {
        let dec = d.join("d.csv");
        if f.run("decode", &[&"decode", &mix, &bytes, &"-o", &dec])
            .is_some()
        {
            f.0.extend(decoded_as_sampled(p, &csv, &dec));
        }
    }
    f.run(
        "faults (its clean run of this mix)",
        &[&"faults", &mix, &"--quiet", &"--false-alarm-mixes", &"1"],
    );
    if wide {
        prove(&mut f, &mix);
    }
    match f.0.is_empty() {
        true => Ok(true),
        false => Err(format!(
            "{p:?} (seed {seed}):\n  {}\n--- mix:\n{text}",
            f.0.join("\n  ")
        )),
    }
}

/// A Verilator run of the scene writing the VCD window `(from, to, path)`
/// and `out`'s files; whether it passed.
fn verilator(
    f: &mut Faults,
    mix: &Path,
    scene: &[&dyn AsRef<std::ffi::OsStr>],
    (from, to, vcd): (&str, &str, &Path),
    out: &[&dyn AsRef<std::ffi::OsStr>],
) -> bool {
    let mut a: Vec<&dyn AsRef<std::ffi::OsStr>> = vec![
        &"sim",
        &mix,
        &"--quiet",
        &"--frames",
        &FRAMES,
        &"--backend",
        &"verilator",
        &"--from",
        &from,
        &"--to",
        &to,
        &"--vcd",
        &vcd,
    ];
    a.extend(out.iter().copied());
    a.extend(scene.iter().copied());
    f.run(
        &format!("sim --backend verilator --from {from} --to {to}"),
        &a,
    )
    .is_some()
}

/// `prove` proves (exit 0), or refuses or is bounded naming what it left
/// out: never a counterexample.
fn prove(f: &mut Faults, mix: &Path) {
    let out = slotforge(&[&"prove", &mix, &"--json", &"--quiet"]);
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap_or_default();
    let status = j["status"].as_str().unwrap_or("");
    let named = j["not_covered"].as_array().is_some_and(|a| !a.is_empty())
        || j["reason"].as_str().is_some_and(|r| !r.is_empty());
    match status {
        "proved" => {}
        "bounded" | "refused" if named => {}
        _ => f.0.push(format!(
            "prove: status {status:?} (exit {:?}): {}",
            out.status.code(),
            String::from_utf8_lossy(&out.stderr)
        )),
    }
}

/// Runs `points` (seeded by their index) and fails with every broken one;
/// at most a third may be refused, so the matrix keeps its meaning.
fn draw(points: &[Point], seed0: u64, wide: bool) {
    let (mut refused, mut bad) = (0, vec![]);
    for (i, p) in points.iter().enumerate() {
        match through(p, seed0 + i as u64, wide) {
            Ok(true) => {}
            Ok(false) => refused += 1,
            Err(e) => bad.push(e),
        }
    }
    assert!(
        bad.is_empty(),
        "{} of {} mixes broken:\n{}",
        bad.len(),
        points.len(),
        bad.join("\n\n")
    );
    assert!(
        refused * 3 <= points.len(),
        "{refused} of {} refused",
        points.len()
    );
}

/// The quick draw: the first points of the pairwise cover.
#[test]
fn a_quick_draw_of_the_feature_matrix_passes_end_to_end() {
    draw(&matrix::pairwise(1)[..4], 1, false);
}

/// The cover's mixes with a fronted AD7689 in a mix with modes (the audit
/// refused them before: matrix-19, -20 and -22 of `matrix_mixes`), each
/// through the property (`make test-long` adds Icarus and `prove`).
#[test]
fn the_covers_fronted_converters_with_modes_pass_end_to_end() {
    let pts = matrix::pairwise(1);
    let fronted: Vec<(u64, &Point)> = (1u64..)
        .zip(pts.iter())
        .filter(|(_, p)| p.modes != Modes::None && p.converter == matrix::Converter::Ad7689Front)
        .collect();
    assert!(
        fronted.len() >= 2,
        "{} such mixes in the cover",
        fronted.len()
    );
    for (seed, p) in fronted {
        assert_eq!(through(p, seed, false), Ok(true), "matrix-{seed}: {p:?}");
    }
}

/// The whole pairwise cover and free draws, with Icarus and `prove`.
#[test]
#[ignore = "the wide feature matrix: make test-long"]
fn the_whole_feature_matrix_passes_end_to_end() {
    let mut pts = matrix::pairwise(1);
    pts.extend(matrix::random(2, 12));
    draw(&pts, 100, true);
}
