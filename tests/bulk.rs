//! Bulk channels end to end: a mix written with `name = "T{0..47}"` gives
//! the same audit (text and JSON) and the same Verilog as the mix written
//! out channel by channel, byte for byte apart from the file's name; for
//! every preset rewritten in bulk form and for random bulk mixes.

use std::fmt::Write as _;
use std::path::Path;

use crate::common_cli::{root, slotforge};
use crate::common_presets::presets;

/// `audit` (text and `--json`): exit code and stdout with the file's path
/// and name taken out; `verilog`'s files by name.
fn outputs(mix: &Path, out: &Path) -> Vec<(String, String)> {
    let strip = |s: &[u8]| {
        String::from_utf8_lossy(s)
            .replace(&mix.display().to_string(), "MIX")
            .replace(&*mix.file_stem().unwrap().to_string_lossy(), "NAME")
    };
    let mut all = Vec::new();
    for json in [false, true] {
        let mut cmd = slotforge();
        cmd.arg("audit").arg(mix);
        if json {
            cmd.arg("--json");
        }
        let o = cmd.output().unwrap();
        all.push((
            format!("audit json={json} exit"),
            format!("{:?}", o.status.code()),
        ));
        all.push((format!("audit json={json}"), strip(&o.stdout)));
        all.push((format!("audit json={json} stderr"), strip(&o.stderr)));
    }
    let o = slotforge()
        .arg("verilog")
        .arg(mix)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap();
    all.push(("verilog exit".into(), format!("{:?}", o.status.code())));
    let mut files: Vec<_> = std::fs::read_dir(out)
        .map(|d| d.map(|e| e.unwrap().path()).collect())
        .unwrap_or_default();
    files.sort();
    for f in files {
        let name = f.file_name().unwrap().to_string_lossy().to_string();
        all.push((name, strip(&std::fs::read(&f).unwrap())));
    }
    all
}

/// Both mixes' outputs, compared one by one so a failure names the output.
fn assert_same(bulk_text: &str, long_text: &str, what: &str) {
    let dir = tempfile::tempdir().unwrap();
    let (bulk, long) = (
        dir.path().join("bulkform.toml"),
        dir.path().join("writtenout.toml"),
    );
    std::fs::write(&bulk, bulk_text).unwrap();
    std::fs::write(&long, long_text).unwrap();
    let b = outputs(&bulk, &dir.path().join("vb"));
    let l = outputs(&long, &dir.path().join("vl"));
    assert_eq!(b.len(), l.len(), "{what}: files {b:?}");
    for ((bn, bo), (ln, lo)) in b.iter().zip(&l) {
        assert_eq!(bn, ln, "{what}");
        assert!(
            bo == lo,
            "{what}: {bn} differs:\n--- bulk\n{bo}\n--- written out\n{lo}"
        );
    }
}

#[test]
fn presets_in_bulk_form_audit_and_emit_as_written_out() {
    let mut rewritten = 0;
    for preset in presets(&root()) {
        let text = std::fs::read_to_string(&preset).unwrap();
        let (bulk, runs) = testkit::bulk::bulkify(&text);
        if runs == 0 {
            continue;
        }
        rewritten += 1;
        let name = preset.display().to_string();
        if name.ends_with("eskin34.toml") {
            // the 25 + 9 + 2 numbered channels as three tables
            assert_eq!(runs, 3, "{bulk}");
            assert!(bulk.contains("name = \"CH{1..25}\""), "{bulk}");
            assert_eq!(bulk.matches("[[channel]]").count(), 8, "{bulk}");
        }
        assert_same(&bulk, &text, &name);
    }
    // eskin34 and its UART and AXI4-Stream variants at least
    assert!(rewritten >= 3, "only {rewritten} presets have runs");
}

/// A random mix written with ranges: rows of channels on random branches
/// at random rates, some with a first input (counting up), some automatic.
fn random_bulk_mix(seed: u64) -> String {
    let mut draw = testkit::modemix::Draw::new(seed);
    let mut next = |n: u64| draw.below(n);
    let mut t = String::from(
        "name = \"random\"\n[clock]\nhz = 48_000_000\n[frame]\nperiod_us = 2_000\nslice_us = 1_000\n",
    );
    let nb = 1 + next(3);
    for b in 0..nb {
        let _ = write!(
            t,
            "[[branch]]\nname = \"b{b}\"\nadc = \"ad7940\"\nmux = \"tmux1108\"\nmux_devices = 4\nsettle_ns = 1_000\n"
        );
    }
    let mut next_input = vec![0; nb as usize];
    for row in 0..1 + next(4) {
        let b = next(nb) as usize;
        let count = 1 + next(8);
        let first = next(20);
        let rate = [500, 1_000, 2_000][next(3) as usize];
        let _ = write!(
            t,
            "[[channel]]\nname = \"r{row}_{{{first}..{}}}\"\nbranch = \"b{b}\"\nrate_hz = {rate}\n",
            first + count - 1
        );
        // explicit inputs after every automatic one of the branch so far
        if next(2) == 0 && next_input[b] + count <= 32 {
            let _ = writeln!(
                t,
                "input = {}",
                32 - count - next(32 - count + 1).min(next_input[b])
            );
        }
        next_input[b] += count;
        t.push('\n');
    }
    t
}

#[test]
fn random_bulk_mixes_audit_and_emit_as_written_out() {
    let mut feasible = 0;
    for seed in 1..=6 {
        let bulk = random_bulk_mix(seed);
        let long = testkit::bulk::expand(&bulk);
        assert!(long.matches("[[channel]]").count() >= bulk.matches("[[channel]]").count());
        if lut_gen::parse(Path::new("r.toml"), &long).is_ok() {
            feasible += 1;
        }
        assert_same(&bulk, &long, &format!("seed {seed}:\n{bulk}"));
    }
    assert!(feasible >= 3, "only {feasible} of the random mixes parse");
}
