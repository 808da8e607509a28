//! `sim --link-bytes` and `decode`, end to end: the bytes a run's link
//! carried (UART characters read off `link_tx`, AXI4-Stream beats) decode
//! to the run's own `--samples`, sample for sample, with the same
//! `sampled_s`; the packet still in flight when the run ends is counted as
//! such (exit 0); a byte flipped on the way is a loss (exit 1).  On both
//! link presets, random mixes given a `[link]`, and every back end.

use std::path::{Path, PathBuf};

use crate::common_cli::{root, slotforge};
use crate::tools;

/// One CSV's rows as (channel, value, sampled_s), and the strobe cycle of
/// each (`sim --samples` only).
struct Rows {
    samples: Vec<(String, String, String)>,
    strobes: Vec<u64>,
}

fn sim_rows(csv: &str) -> Rows {
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("cycle,sampled_s,channel,value"));
    let mut r = Rows {
        samples: Vec::new(),
        strobes: Vec::new(),
    };
    for l in lines {
        let f: Vec<&str> = l.split(',').collect();
        r.strobes.push(f[0].parse().unwrap());
        r.samples.push((f[2].into(), f[3].into(), f[1].into()));
    }
    r
}

fn decoded_rows(csv: &str) -> Vec<(String, String, String)> {
    let mut lines = csv.lines();
    // a mix with modes has a `mode` column after the slice
    let m = match lines.next() {
        Some("frame,slice,channel,value,sampled_s") => 0,
        Some("frame,slice,mode,channel,value,sampled_s") => 1,
        h => panic!("decode's header: {h:?}"),
    };
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (f[2 + m].into(), f[3 + m].into(), f[4 + m].into())
        })
        .collect()
}

/// `sim MIX --backend B --frames N --samples --link-bytes`: the bytes and
/// the samples' CSV text.
fn sim(mix: &Path, backend: &str, frames: u64, dir: &Path) -> (Vec<u8>, String) {
    sim_with(mix, backend, frames, dir, &[])
}

/// [`sim`] with more options (`--modes`, `--stimulus`).
fn sim_with(
    mix: &Path,
    backend: &str,
    frames: u64,
    dir: &Path,
    extra: &[&str],
) -> (Vec<u8>, String) {
    let (csv, bin) = (
        dir.join(format!("{backend}.csv")),
        dir.join(format!("{backend}.bin")),
    );
    slotforge()
        .arg("sim")
        .arg(mix)
        .args(["--backend", backend, "--frames", &frames.to_string()])
        .args(["--quiet", "--samples"])
        .arg(&csv)
        .args(extra)
        .arg("--link-bytes")
        .arg(&bin)
        .assert()
        .code(0);
    (
        std::fs::read(&bin).unwrap(),
        std::fs::read_to_string(&csv).unwrap(),
    )
}

/// `decode MIX BYTES --json`: exit code, counts, rows.
fn decode(mix: &Path, bytes: &[u8], dir: &Path) -> (i32, serde_json::Value, String) {
    let (cap, out) = (dir.join("cap.bin"), dir.join("dec.csv"));
    std::fs::write(&cap, bytes).unwrap();
    let o = slotforge()
        .arg("decode")
        .arg(mix)
        .arg(&cap)
        .arg("-o")
        .arg(&out)
        .arg("--json")
        .output()
        .unwrap();
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).expect("decode --json");
    let csv = std::fs::read_to_string(&out).unwrap();
    (o.status.code().unwrap(), j, csv)
}

/// The mix's schedule, for the window every sample must have left in.
fn schedule(mix: &Path) -> lut_gen::Schedule {
    let m = lut_gen::load(mix).unwrap();
    lut_gen::synthesize(&m).unwrap()
}

/// `sim --link-bytes` decodes to `sim --samples`: the decoded rows are the
/// run's first rows, equal in channel, value and sampled_s, every sample
/// strobed before the last two slices among them; the rest is in flight
/// (exit 0).  A byte flipped in a record is a loss (exit 1).  Returns the
/// bytes.
fn bytes_decode_to_the_samples(mix: &Path, backend: &str, frames: u64) -> Vec<u8> {
    bytes_decode_with(mix, backend, frames, &[]).0
}

/// [`bytes_decode_to_the_samples`] with more `sim` options; the bytes and
/// the decoded CSV.
fn bytes_decode_with(mix: &Path, backend: &str, frames: u64, extra: &[&str]) -> (Vec<u8>, String) {
    let dir = tempfile::tempdir().unwrap();
    let (bytes, csv) = sim_with(mix, backend, frames, dir.path(), extra);
    let sim = sim_rows(&csv);
    let (code, j, out) = decode(mix, &bytes, dir.path());
    let what = format!("{} on {backend}: {j}", mix.display());
    assert_eq!(code, 0, "{what}");
    assert_eq!(j["ok"], true, "{what}");
    assert_eq!(j["bytes"], bytes.len(), "{what}");
    for k in ["crc_errors", "lost_packets", "resyncs", "skipped_bytes"] {
        assert_eq!(j[k], 0, "{k}: {what}");
    }
    let dec = decoded_rows(&out);
    assert_eq!(j["samples"], dec.len(), "{what}");
    assert!(!dec.is_empty() && dec.len() <= sim.samples.len(), "{what}");
    assert_eq!(dec[..], sim.samples[..dec.len()], "{what}");
    assert!(dec.iter().all(|r| !r.2.is_empty()), "every sample timed");
    // what is not decoded left in the run's last two slices (in flight)
    let s = schedule(mix);
    let late = frames * s.grid.frame_cycles - 2 * s.grid.slice_cycles;
    assert!(
        sim.strobes[dec.len()..].iter().all(|&c| c >= late),
        "{} of {} samples decoded: {what}",
        dec.len(),
        sim.samples.len()
    );
    if dec.len() < sim.samples.len() {
        assert!(j["in_flight_bytes"].as_u64().unwrap() > 0, "{what}");
    }

    // a flipped bit in the first record of the middle packet with records
    // (the stream starts at a header, so words are 4-byte aligned): a loss
    let heads: Vec<usize> = (0..bytes.len())
        .step_by(4)
        .filter(|&i| bytes[i] == link::format::SYNC && bytes.get(i + 4) != Some(&link::format::END))
        .collect();
    let at = heads[heads.len() / 2] + 4 + 3;
    let mut bad = bytes.clone();
    bad[at] ^= 0x10;
    let (code, j, bad_out) = decode(mix, &bad, dir.path());
    assert_eq!(code, 1, "flipped: {what}");
    assert_eq!(j["ok"], false, "{j}");
    assert!(j["crc_errors"].as_u64().unwrap() >= 1, "{j}");
    assert!(decoded_rows(&bad_out).len() < dec.len(), "{j}");
    (bytes, out)
}

/// The `mode` column of a decoded CSV (a mix with modes), row by row.
fn mode_column(csv: &str) -> Vec<String> {
    let mut lines = csv.lines();
    assert_eq!(
        lines.next(),
        Some("frame,slice,mode,channel,value,sampled_s")
    );
    lines
        .map(|l| l.split(',').nth(2).unwrap().to_string())
        .collect()
}

/// A switching run's link (pin select under `--modes`, auto under a
/// touch) decodes to the run's samples with their `sampled_s` (each mode's
/// schedule, and the frame before's for the samples a packet carries
/// over), and the `mode` column shows every mode the run went through.
#[test]
fn mode_mixes_bytes_decode_with_their_modes() {
    let dir = tempfile::tempdir().unwrap();
    let pin = dir.path().join("modes-pin-uart.toml");
    let text = std::fs::read_to_string(root().join("testkit/mixes/modes-pin.toml")).unwrap();
    std::fs::write(&pin, text + "\n[link]\nkind = \"uart\"\nbaud = 1_000_000\n").unwrap();
    let auto = root().join("testkit/mixes/modes-auto.toml");
    for (mix, frames, extra, want) in [
        (
            &pin,
            10,
            ["--modes", "2=slow,5=fast"],
            &["fast", "slow"][..],
        ),
        (
            &auto,
            14,
            ["--stimulus", "touch:T0,T2@2-6"],
            &["rest", "touch"][..],
        ),
    ] {
        let (_, csv) = bytes_decode_with(mix, "model", frames, &extra);
        let mut modes = mode_column(&csv);
        modes.dedup();
        assert_eq!(
            modes.first().map(String::as_str),
            Some(want[0]),
            "{modes:?}"
        );
        assert!(modes.len() >= 3, "{}: {modes:?}", mix.display());
        for m in want {
            assert!(modes.iter().any(|x| x == m), "{m}: {modes:?}");
        }
    }
}

#[test]
fn uart_preset_bytes_decode_to_its_samples() {
    bytes_decode_to_the_samples(&root().join("mixes/eskin34-uart.toml"), "rusthdl", 2);
}

#[test]
fn axis_preset_bytes_decode_to_its_samples_on_verilator() {
    if !tools::require_tool("verilator") {
        return;
    }
    bytes_decode_to_the_samples(&root().join("mixes/eskin34-axis.toml"), "verilator", 2);
}

/// Random mixes (the campaign's generator) given a `[link]`: the first
/// `n` whose schedule and link plan are feasible, written to `dir`.
fn random_link_mixes(dir: &Path, link: &str, n: usize) -> Vec<PathBuf> {
    (1..200u64)
        .filter_map(|seed| {
            let text = campaign::random_mix(seed, &campaign::Shape::default()) + link;
            let path = dir.join(format!("random-{seed}.toml"));
            let m = lut_gen::parse(&path, &text).ok()?;
            let s = lut_gen::synthesize(&m).ok()?;
            lut_gen::plan_link(&s)?.ok()?;
            std::fs::write(&path, text).unwrap();
            Some(path)
        })
        .take(n)
        .collect()
}

#[test]
fn random_link_mixes_bytes_decode_to_their_samples() {
    let dir = tempfile::tempdir().unwrap();
    let uart = random_link_mixes(
        dir.path(),
        "\n[link]\nkind = \"uart\"\nbaud = 3_000_000\nparity = \"odd\"\n",
        3,
    );
    let axis = random_link_mixes(
        dir.path(),
        "\n[link]\nkind = \"axis\"\ntlast = \"frame\"\n",
        2,
    );
    assert_eq!((uart.len(), axis.len()), (3, 2));
    for mix in uart.iter().chain(&axis) {
        bytes_decode_to_the_samples(mix, "rusthdl", 3);
    }
}

/// Every back end with the link's pins writes the same bytes: the model
/// (cycle level), rusthdl, Verilator and Icarus, on the small two-branch
/// mix (fast in every simulator) with a UART and with an AXI4-Stream link.
#[test]
fn every_back_end_writes_the_same_link_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let tiny = std::fs::read_to_string(crate::common_cli::tiny()).unwrap();
    for (name, link) in [
        ("uart", "\n[link]\nkind = \"uart\"\nbaud = 1_000_000\n"),
        ("axis", "\n[link]\nkind = \"axis\"\n"),
    ] {
        let mix = dir.path().join(format!("tiny-{name}.toml"));
        std::fs::write(&mix, tiny.clone() + link).unwrap();
        let reference = bytes_decode_to_the_samples(&mix, "model", 3);
        let (bytes, _) = sim(&mix, "rusthdl", 3, dir.path());
        assert_eq!(bytes, reference, "rusthdl vs model: {name}");
        for (backend, tool) in [("verilator", "verilator"), ("icarus", "iverilog")] {
            if tools::require_tool(tool) {
                let (bytes, _) = sim(&mix, backend, 3, dir.path());
                assert_eq!(bytes, reference, "{backend} vs model: {name}");
            }
        }
    }
}

/// A mix without a `[link]` is refused before the run (exit 2), nothing
/// written; the text summary of a capture says what is in flight.
#[test]
fn link_bytes_need_a_link_and_the_summary_says_what_is_in_flight() {
    let dir = tempfile::tempdir().unwrap();
    let bin = dir.path().join("none.bin");
    let o = slotforge()
        .arg("sim")
        .arg(root().join("mixes/eskin34.toml"))
        .args(["--frames", "1", "--link-bytes"])
        .arg(&bin)
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(
        e.contains("--link-bytes") && e.contains("eskin34.toml has no [link]"),
        "{e}"
    );
    assert_eq!(e.lines().count(), 1, "{e}");
    assert!(!bin.exists());

    let mix = root().join("mixes/eskin34-uart.toml");
    let (bytes, _) = sim(&mix, "model", 1, dir.path());
    let cap = dir.path().join("cap.bin");
    std::fs::write(&cap, &bytes).unwrap();
    let o = slotforge()
        .arg("decode")
        .arg(&mix)
        .arg(&cap)
        .args(["-o", "-"])
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{e}");
    assert!(
        e.contains(": clean;") && e.contains("still in flight when the capture ends"),
        "{e}"
    );
}
