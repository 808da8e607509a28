//! The emitted Verilog reads as blocks: on every preset and on random mixes,
//! no identifier has a `$`, no module is declared twice, every module the
//! header's block map names is declared, the per-mix constants the header
//! lists are the schedule's, and the file lints clean.

use std::collections::BTreeSet;
use std::path::Path;
use std::process::Command;

use lut_gen::Schedule;

use crate::tools;

fn declared(v: &str) -> Vec<String> {
    v.lines()
        .filter_map(|l| l.strip_prefix("module "))
        .map(|r| {
            r.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == '$'))
                .next()
                .unwrap()
                .to_string()
        })
        .collect()
}

/// Every `slotforge_*` name in the header's block map (before the wrapper).
fn named_in_header(v: &str) -> BTreeSet<String> {
    let head = &v[..v.find("`default_nettype none").unwrap()];
    head.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == '<' || c == '>'))
        .filter(|w| w.starts_with("slotforge_") && !w.contains('<'))
        .map(str::to_string)
        .collect()
}

/// The header's value of constant `key` (`//   key   value`).
fn header_value(v: &str, key: &str) -> u64 {
    let line = v
        .lines()
        .find(|l| {
            l.strip_prefix("//   ")
                .is_some_and(|r| r.split_whitespace().next() == Some(key))
        })
        .unwrap_or_else(|| panic!("no constant {key} in the header"));
    line.split_whitespace().nth(2).unwrap().parse().unwrap()
}

fn check(tag: &str, s: &Schedule, lint: bool) {
    let v = hdl::emit(s, None).unwrap().verilog().to_string();
    // no `$` anywhere: not in identifiers, and the file has no system task
    assert!(
        !v.contains('$'),
        "{tag}: a `$` in\n{}",
        v.lines().find(|l| l.contains('$')).unwrap()
    );
    let mods = declared(&v);
    let set: BTreeSet<&String> = mods.iter().collect();
    assert_eq!(
        set.len(),
        mods.len(),
        "{tag}: a module declared twice: {mods:?}"
    );
    for m in named_in_header(&v) {
        assert!(
            mods.contains(&m),
            "{tag}: the header names {m}, which is not declared"
        );
    }
    for (b, bp) in s.branches.iter().enumerate() {
        let line = v
            .lines()
            .find(|l| l.starts_with(&format!("// SPI timing of branch {b} ")))
            .unwrap_or_else(|| panic!("{tag}: the header says nothing of branch {b}'s SPI timing"));
        for (k, x) in [
            ("sclk_div", bp.spi.sclk_div),
            ("setup_cycles", bp.spi.setup_cycles),
            ("read_cycles", bp.spi.read_cycles),
        ] {
            assert!(
                line.contains(&format!(" {k} {x} ")) || line.contains(&format!(" {k} {x},")),
                "{tag}: {line}"
            );
        }
        let m = line
            .rsplit("search \"")
            .next()
            .unwrap()
            .trim_end_matches(['"', ')']);
        // the module the search finds states this branch's numbers too
        let at = 1 + v
            .find(&format!("\n{m}"))
            .unwrap_or_else(|| panic!("{tag}: no line starts with `{m}`"));
        let note: String = v[at..].lines().skip(1).take(4).collect();
        assert!(
            note.contains(&format!("branch {b} ")) || note.contains(&format!(", {b} ")),
            "{tag}: {note}"
        );
        assert!(
            note.contains(&format!("sclk_div {} ", bp.spi.sclk_div)),
            "{tag}: {note}"
        );
        assert!(
            note.contains(&format!("read_cycles {},", bp.spi.read_cycles)),
            "{tag}: {note}"
        );
    }
    let g = &s.grid;
    assert_eq!(header_value(&v, "clock_hz"), g.clock_hz, "{tag}");
    assert_eq!(header_value(&v, "slot_cycles"), g.slot_cycles, "{tag}");
    assert_eq!(
        header_value(&v, "slots_per_slice"),
        g.slots_per_slice,
        "{tag}"
    );
    assert_eq!(
        header_value(&v, "slices_per_frame"),
        g.slices_per_frame,
        "{tag}"
    );
    assert_eq!(header_value(&v, "frame_cycles"), g.frame_cycles, "{tag}");
    if lint {
        lint_clean(tag, &v);
    }
}

fn lint_clean(tag: &str, v: &str) {
    if !tools::require_tools(&["verilator", "iverilog"]) {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("slotforge_top.v"), v).unwrap();
    let run = |cmd: &mut Command| {
        let o = cmd.current_dir(dir.path()).output().unwrap();
        let t = format!(
            "{}{}",
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        );
        (o.status.success(), t)
    };
    let (ok, t) = run(Command::new("verilator").args(["--lint-only", "-Wall", "slotforge_top.v"]));
    assert!(
        ok && !t.contains("%Warning"),
        "verilator -Wall on {tag}:\n{t}"
    );
    let (ok, t) = run(Command::new("iverilog").args([
        "-g2005",
        "-Wall",
        "-o",
        "/dev/null",
        "slotforge_top.v",
    ]));
    assert!(ok && t.trim().is_empty(), "iverilog -Wall on {tag}:\n{t}");
}

/// Every preset (their lint is `hdl`'s tools gates).
#[test]
fn every_preset_reads_as_blocks() {
    for path in testkit::presets::presets(&testkit::root()) {
        let text = std::fs::read_to_string(&path).unwrap();
        let s = lut_gen::synthesize(&lut_gen::parse(&path, &text).unwrap()).unwrap();
        check(&path.display().to_string(), &s, false);
    }
}

/// Random mixes (one to four branches, shared and distinct SPI timings),
/// linted too.
#[test]
fn random_mixes_read_as_blocks() {
    let mut tested = 0;
    for seed in 0..8 {
        let text = campaign::random_mix(seed, &campaign::Shape::default());
        let Ok(mix) = lut_gen::parse(Path::new("rand.toml"), &text) else {
            continue;
        };
        let Ok(s) = lut_gen::synthesize(&mix) else {
            continue;
        };
        tested += 1;
        check(&format!("random seed {seed}"), &s, tested <= 4);
    }
    assert!(tested >= 4, "only {tested} of 8 random mixes are feasible");
}

/// Mixes with converters that take a command word (the test mixes and a
/// commanded random mix): each command unit is a module the header names,
/// and the text lints clean.
#[test]
fn commanded_mixes_read_as_blocks() {
    for name in ["cmd-mcp3208", "cmd-ad7689", "cmd-both", "cmd-ads7953"] {
        let s = lut_gen::synthesize(&lut_gen::load(&testkit::mix(name)).unwrap()).unwrap();
        let v = hdl::emit(&s, None).unwrap().verilog().to_string();
        let units = (0..s.branches.len()).filter(|&b| s.has_command(b)).count();
        for i in 0..units {
            assert!(
                named_in_header(&v).contains(&format!("slotforge_cmd{i}")),
                "{name}"
            );
        }
        check(name, &s, true);
    }
}
