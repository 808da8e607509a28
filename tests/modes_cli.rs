//! The commands past the simulation on mixes with modes: `synth` places
//! them, `golden` replays a recorded scene on every back end (and a
//! different switch differs), `faults` injects into the gateware and its
//! Verilog with the switching scenario (`check --map`:
//! tests/mode_captures.rs).  Each on the shared pin and auto mixes and on random mode mixes
//! drawn here.

use std::path::{Path, PathBuf};

use predicates::prelude::*;
use serde_json::Value;

use crate::common_cli::{column, root, slotforge};
use crate::tools;

fn shared(name: &str) -> PathBuf {
    root().join("testkit/mixes").join(format!("{name}.toml"))
}

/// The first random mode mix from `seed` on with the wanted select that
/// schedules and fits the pin contract, written into `dir`.
fn random_mode_mix(dir: &Path, seed: u64, select: lut_gen::ModeSelect) -> PathBuf {
    random_mode_mix_at(dir, seed, select, RANDOM_HZ)
}

/// The clock of `testkit::modemix`'s random mode mixes.
const RANDOM_HZ: &str = "8_000_000";

/// [`random_mode_mix`] clocked at `hz` (the same draw: every cycle a
/// campaign runs costs, and which faults a mix shows does not depend on
/// its clock).
fn random_mode_mix_at(dir: &Path, seed: u64, select: lut_gen::ModeSelect, hz: &str) -> PathBuf {
    let at = |t: String| {
        let clock = format!("hz = {RANDOM_HZ}");
        assert!(t.contains(&clock), "{t}");
        t.replace(&clock, &format!("hz = {hz}"))
    };
    let (k, text) = (seed..seed + 100)
        .filter_map(|k| Some((k, at(testkit::modemix::random_mode_mix(k)?))))
        .find(|(_, t)| {
            lut_gen::parse(Path::new("r.toml"), t)
                .ok()
                .and_then(|m| lut_gen::synthesize(&m).ok())
                .is_some_and(|s| {
                    lut_gen::Layout::fits(&s).is_ok()
                        && s.mode_plan().is_some_and(|p| p.select == select)
                })
        })
        .expect("a random mode mix");
    let p = dir.join(format!("random-modes-{k}.toml"));
    std::fs::write(&p, text).unwrap();
    p
}

fn modes_of(mix: &Path) -> Vec<String> {
    lut_gen::load(mix).unwrap().modes.unwrap().names
}

fn json(out: &std::process::Output) -> Value {
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "{e}: {}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        )
    })
}

/// `synth` places a mix with modes on the iCE40 board, its mode ports on
/// the board's pins, and says which modes the gateware holds; the table
/// says the same.  `make test` places the pin preset and a random pin mix
/// (the table on the random one); the auto preset, with the table of each,
/// is `make test-long`'s (each synthesis is 2 to 3 s of yosys and nextpnr).
#[test]
fn synth_places_mode_mixes_with_their_mode_ports_on_pins() {
    if !tools::require_tools(&["yosys", "nextpnr-ice40"]) {
        return;
    }
    let d = tempfile::tempdir().unwrap();
    let random = random_mode_mix(d.path(), 7, lut_gen::ModeSelect::Pin);
    synth_places(d.path(), &shared("modes-pin"), false);
    synth_places(d.path(), &random, true);
}

#[test]
#[ignore = "long: make test-long (the auto preset, and the table of each)"]
fn synth_places_the_auto_preset_and_tables_each_mixs_modes() {
    if !tools::require_tools(&["yosys", "nextpnr-ice40"]) {
        return;
    }
    let d = tempfile::tempdir().unwrap();
    for mix in [shared("modes-pin"), shared("modes-auto")] {
        synth_places(d.path(), &mix, true);
    }
}

/// `synth --json` of `mix` names its modes and select and puts every mode
/// port on a pin; with `table`, the text table's `modes` row names them too.
fn synth_places(d: &Path, mix: &Path, table: bool) {
    let out = d.join(mix.file_stem().unwrap());
    let o = slotforge()
        .args(["synth", "--json", "-o"])
        .arg(&out)
        .arg(mix)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v = json(&o);
    let s = lut_gen::synthesize(&lut_gen::load(mix).unwrap()).unwrap();
    let plan = s.mode_plan().unwrap();
    assert_eq!(v["modes"]["names"], serde_json::json!(plan.names), "{v}");
    assert_eq!(v["modes"]["select"], plan.select.name(), "{v}");
    assert!(v["logic_cells"].as_u64().unwrap() > 0, "{v}");
    // every mode port bit has a pin in the constraint file nextpnr read
    let pcf = std::fs::read_to_string(out.join("slotforge.pcf")).unwrap();
    let l = lut_gen::Layout::new(&s);
    for p in l.mode_ports() {
        assert!(
            pcf.lines()
                .any(|x| x.starts_with("set_io") && x.contains(&format!(" {}", p.name))),
            "{} has no pin:\n{pcf}",
            p.name
        );
    }
    if !table {
        return;
    }
    let t = slotforge()
        .args(["synth", "-o"])
        .arg(d.join("text"))
        .arg(mix)
        .output()
        .unwrap();
    let t = String::from_utf8_lossy(&t.stdout).to_string();
    let row = t.lines().find(|l| l.starts_with("  modes ")).unwrap();
    assert!(row.contains(&plan.names.join(", ")), "{t}");
}

/// `golden --update` under a scene records it in the log's header; a run
/// without options replays it on every back end and matches; a run with
/// another switch differs (exit 1), and says which scene each was. Icarus
/// (eight frames a run, 3.5 to 6 s of CPU) replays the pin preset's scene
/// here, the auto preset's and the random mixes' too in `make test-long`.
/// Verilator (a model to build for each mix: g++ was two thirds of this
/// test's CPU) replays the presets' scenes here, the random mixes' too in
/// `make test-long`; the model and rust-hdl replay every mix's.
#[test]
fn golden_of_a_mode_mix_replays_its_scene_on_every_back_end() {
    golden_replays_its_scene(1, 2);
}

#[test]
#[ignore = "long: make test-long (Verilator and Icarus replay every mix's scene)"]
fn golden_of_a_mode_mix_replays_its_scene_on_every_back_end_icarus_on_each() {
    golden_replays_its_scene(usize::MAX, usize::MAX);
}

/// The golden scenes of the two presets and two random mode mixes, replayed
/// on every back end; Icarus replays the first `on_icarus` of them,
/// Verilator the first `on_verilator`.
fn golden_replays_its_scene(on_icarus: usize, on_verilator: usize) {
    if !tools::require_tools(&["verilator", "iverilog"]) {
        return;
    }
    let d = tempfile::tempdir().unwrap();
    let pin_random = random_mode_mix(d.path(), 3, lut_gen::ModeSelect::Pin);
    let auto_random = random_mode_mix(d.path(), 3, lut_gen::ModeSelect::Auto);
    let pin_scene = |m: &[String]| format!("2={},5={}", m[1], m[0]);
    let cases: Vec<(PathBuf, Vec<String>, Vec<String>)> = vec![
        (
            shared("modes-pin"),
            vec!["--modes".into(), pin_scene(&modes_of(&shared("modes-pin")))],
            vec!["--modes".into(), "3=slow,5=fast".into()],
        ),
        (
            shared("modes-auto"),
            vec!["--stimulus".into(), "touch:T{0..3}@1-4".into()],
            vec!["--stimulus".into(), "touch:T{0..3}@2-4".into()],
        ),
        (
            pin_random.clone(),
            vec!["--modes".into(), pin_scene(&modes_of(&pin_random))],
            vec!["--modes".into(), format!("1={}", modes_of(&pin_random)[1])],
        ),
        (
            auto_random,
            vec!["--stimulus".into(), "touch:c0@1-3".into()],
            vec!["--stimulus".into(), "pattern".into()],
        ),
    ];
    for (i, (mix, scene, other)) in cases.into_iter().enumerate() {
        let name = lut_gen::load(&mix).unwrap().name;
        let dir = d.path().join("golden");
        std::fs::create_dir_all(dir.join(&name)).unwrap();
        std::fs::write(dir.join(&name).join("golden.toml"), "frames = 8\n").unwrap();
        let golden = || {
            let mut c = slotforge();
            c.args(["golden", "--quiet", "--dir"]).arg(&dir).arg(&mix);
            c
        };
        golden()
            .args(["--backend", "model", "--update"])
            .args(&scene)
            .assert()
            .success();
        let log = std::fs::read_to_string(dir.join(&name).join("events.log")).unwrap();
        assert!(
            log.contains(&format!("# scene {}: {}", scene[0], scene[1])),
            "{log}"
        );
        // the mode in force is logged, and the scene switches it
        let switches = log
            .lines()
            .filter(|l| l.contains(" modes ") && l.contains(" mode "))
            .count();
        assert!(switches >= 2, "{name}: {switches} mode events\n{log}");
        let backends = ["model", "rusthdl", "verilator", "icarus"];
        for backend in backends.into_iter().filter(|&b| match b {
            "icarus" => i < on_icarus,
            "verilator" => i < on_verilator,
            _ => true,
        }) {
            golden()
                .args(["--backend", backend])
                .assert()
                .success()
                .stdout(predicate::str::contains("same as"));
        }
        golden()
            .args(["--backend", "rusthdl"])
            .args(&other)
            .assert()
            .code(1)
            .stdout(
                predicate::str::contains("DIFFERS")
                    .and(predicate::str::contains("recorded under"))
                    .and(predicate::str::contains(other[1].as_str())),
            );
    }
}

/// The campaign on the gateware of a mix with modes runs its switching
/// scenario: every pin class (the `mode` output's too) and every gateware
/// class (mode-stuck built into the mode block too) is caught, the matrix
/// naming the detectors.  `make test` runs it on the pin preset and a
/// random auto mix; sigrok's decodes (each run's every branch, read
/// against the mode of each frame whichever way it was selected) were
/// most of its time, so sigrok judges the pin preset's runs and the
/// random mix is judged by the model and the invariants.  `make
/// test-long` runs the random mix with sigrok and the auto preset.  The
/// random mix runs at 4 MHz here (half its 8 MHz cycles, which were half
/// of this test's time); at 8 MHz in the long twin.
#[test]
fn faults_go_into_the_gateware_of_mode_mixes_and_each_class_is_caught() {
    let d = tempfile::tempdir().unwrap();
    every_class_caught(&shared("modes-pin"), Sigrok::On);
    let random = random_mode_mix_at(d.path(), 11, lut_gen::ModeSelect::Auto, "4_000_000");
    every_class_caught(&random, Sigrok::Off);
    // pin faults need a design in process: a Verilog engine as the target
    // is refused, pointing to --engines
    slotforge()
        .args(["faults", "--backend", "icarus"])
        .arg(shared("modes-pin"))
        .assert()
        .code(2)
        .stderr(predicate::str::contains("--engines icarus"));
}

#[test]
#[ignore = "long: make test-long (the auto preset's campaign, the random auto mix's with sigrok)"]
fn faults_go_into_the_gateware_of_the_auto_preset_and_each_class_is_caught() {
    every_class_caught(&shared("modes-auto"), Sigrok::On);
    let d = tempfile::tempdir().unwrap();
    let random = random_mode_mix(d.path(), 11, lut_gen::ModeSelect::Auto);
    every_class_caught(&random, Sigrok::On);
}

/// Whether sigrok's decodes judge a campaign's runs (off: the test
/// switch `SLOTFORGE_TEST_DISABLE_DETECTOR` leaves them out).
#[derive(Clone, Copy, PartialEq)]
enum Sigrok {
    On,
    Off,
}

/// The campaign on `mix`: every mode pin class caught by the model,
/// mode-stuck in the gateware by the invariants, every class caught; with
/// sigrok on, it judged every run, the clean one included.
fn every_class_caught(mix: &Path, sigrok: Sigrok) {
    let off = if sigrok == Sigrok::Off { "sigrok" } else { "" };
    let (v, code) = faults_with(mix, &[], off);
    for name in ["mode-early", "mode-stuck", "mode-unasked"] {
        let r = row(&v, name, "pins");
        assert_eq!(r["detected"], r["injected"], "{r}");
        assert!(r["detected_by"]["model"].as_u64().unwrap() > 0, "{r}");
    }
    let stuck = row(&v, "mode-stuck", "gateware");
    assert!(
        stuck["detected_by"]["invariants"].as_u64().unwrap() > 0,
        "{stuck}"
    );
    for c in v["classes"].as_array().unwrap() {
        assert_eq!(c["detected"], c["injected"], "{c}");
    }
    if sigrok == Sigrok::On {
        let col = column(&v, "sigrok");
        assert!(col["detected"].as_u64().unwrap() > 0, "{col}");
    }
    assert_eq!(code, Some(0), "{v}");
}

/// `faults --backend rusthdl --quiet --json --false-alarm-mixes 0` of
/// `mix` with `extra`: the campaign and the exit code.
fn faults(mix: &Path, extra: &[&str]) -> (Value, Option<i32>) {
    faults_with(mix, extra, "")
}

/// [`faults`] with the detectors `off` (comma-separated) switched off.
fn faults_with(mix: &Path, extra: &[&str], off: &str) -> (Value, Option<i32>) {
    let o = slotforge()
        .env("SLOTFORGE_TEST_DISABLE_DETECTOR", off)
        .args(["faults", "--quiet", "--json", "--backend", "rusthdl"])
        .args(["--false-alarm-mixes", "0"])
        .args(extra)
        .arg(mix)
        .output()
        .unwrap();
    (json(&o), o.status.code())
}

/// The matrix's row of class `name` at `level`.
fn row<'a>(v: &'a Value, name: &str, level: &str) -> &'a Value {
    v["classes"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["name"] == name && c["level"] == level)
        .unwrap_or_else(|| panic!("{name} at {level}: {v}"))
}

/// With `--engines` one fault of each gateware class (mode-stuck too) runs
/// as the Verilog the emitter writes for it on Verilator and Icarus under
/// the switching scenario, each caught, and the clean Verilog is no false
/// alarm (sigrok decodes each frame in its mode); the deep faults escape
/// simulation by design (exit 1 without `--prove`).
#[test]
#[ignore = "long: make test-long"]
fn gateware_faults_of_a_mode_mix_run_as_verilog_on_both_engines() {
    if !tools::require_tools(&["verilator", "iverilog", "sigrok-cli"]) {
        return;
    }
    let (v, code) = faults(&shared("modes-pin"), &["--engines", "verilator,icarus"]);
    for e in ["verilator", "icarus"] {
        let engines = v["engines"].as_array().unwrap();
        let col = engines.iter().find(|x| x["engine"] == e).unwrap();
        assert!(col["injected"].as_u64().unwrap() >= 5, "{col}");
    }
    let classes = v["classes"].as_array().unwrap();
    for c in classes.iter().filter(|c| c["level"] != "verilog") {
        assert_eq!(c["detected"], c["injected"], "{c}");
    }
    let stuck = row(&v, "mode-stuck", "gateware");
    assert_eq!(stuck["injected"], 3, "rusthdl, verilator, icarus: {stuck}");
    assert_eq!(v["false_alarms"]["rejected"], 0, "{v}");
    assert_eq!(code, Some(1), "{v}");
}

/// A golden records its scene; a run under another scene is not "same",
/// even where the frames the golden covers do not show the difference (a
/// switch after them): it differs, exit 1, and says both scenes.
#[test]
fn a_golden_under_another_scene_is_not_the_same() {
    let d = tempfile::tempdir().unwrap();
    let mix = shared("modes-pin");
    let dir = d.path().join("golden");
    let golden = || {
        let mut c = slotforge();
        c.args(["golden", "--quiet", "--backend", "model", "--dir"])
            .arg(&dir)
            .arg(&mix);
        c
    };
    golden()
        .args(["--modes", "5=slow", "--update"])
        .assert()
        .success();
    // the recorded scene, given again or in other words: the same
    golden()
        .assert()
        .success()
        .stdout(predicate::str::contains("same as"));
    golden()
        .args(["--modes", "5=1"])
        .assert()
        .success()
        .stdout(predicate::str::contains("same as"));
    // a switch at frame 6: frame 0, all the golden covers, is alike
    golden()
        .args(["--modes", "6=slow"])
        .assert()
        .code(1)
        .stdout(
            predicate::str::contains("DIFFERS")
                .and(predicate::str::contains("--modes 5=slow"))
                .and(predicate::str::contains("--modes 6=slow"))
                .and(predicate::str::contains("same as").not()),
        );
}
