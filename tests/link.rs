//! The link to the host from the command line, with independent evidence:
//! sigrok-cli's UART decoder reads `link_tx` from a `sim --vcd` of the
//! eskin34-uart preset; its bytes through `slotforge decode` are the run's
//! `--samples`, sample for sample, with sampling times from the schedule.
//! Also: stdin streaming, a corrupted capture (honest counts), a too-slow
//! baud refused with the minimum, bad `[link]` input.

use std::path::{Path, PathBuf};
use std::process::Command as Process;

// Missing tools fail under CI=true, skip loudly elsewhere.
use crate::common_cli::{root, slotforge};
use crate::tools;

fn preset() -> PathBuf {
    root().join("mixes/eskin34-uart.toml")
}

/// `link_tx` of a slotforge VCD (1 ps timescale) as a one-signal VCD in
/// 10 ns units, which sigrok reads at 100 MHz.
fn link_vcd(src: &str) -> String {
    let id = src
        .lines()
        .find(|l| l.starts_with("$var") && l.split_whitespace().nth(4) == Some("link_tx"))
        .and_then(|l| l.split_whitespace().nth(3))
        .expect("link_tx in the VCD")
        .to_string();
    assert!(src.contains("$timescale 1ps $end"));
    let mut out = judge::wire_header("10ns", "top", &["tx"]);
    let mut t = 0u64;
    let mut last = None;
    for l in src
        .lines()
        .skip_while(|l| !l.starts_with("$enddefinitions"))
    {
        if let Some(ps) = l.strip_prefix('#') {
            t = (ps.parse::<u64>().unwrap() + 5_000) / 10_000;
        } else if l.len() == 1 + id.len() && l.ends_with(&id) && l.as_bytes()[0] != b'b' {
            let v = &l[..1];
            if last != Some(v.to_string()) {
                out.push_str(&format!("#{t}\n{v}!\n"));
                last = Some(v.to_string());
            }
        }
    }
    out.push_str(&format!("#{}\n", t + 1));
    out
}

/// The bytes sigrok's UART decoder reads.
fn sigrok_bytes(vcd: &Path) -> Vec<u8> {
    let out = Process::new("sigrok-cli")
        .args(["-I", "vcd", "-i"])
        .arg(vcd)
        .args(["-P", "uart:rx=tx:baudrate=3000000", "-A", "uart=rx-data"])
        .output()
        .expect("sigrok-cli runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| u8::from_str_radix(l.rsplit(':').next().unwrap().trim(), 16).unwrap())
        .collect()
}

/// CSV rows split into fields, header dropped.
fn rows(text: &str) -> Vec<Vec<String>> {
    text.lines()
        .skip(1)
        .map(|l| l.split(',').map(String::from).collect())
        .collect()
}

fn decode_json(mix: &Path, cap: &Path, out: &Path) -> (i32, serde_json::Value) {
    let o = slotforge()
        .arg("decode")
        .arg(mix)
        .arg(cap)
        .arg("-o")
        .arg(out)
        .arg("--json")
        .output()
        .unwrap();
    let j = serde_json::from_slice(&o.stdout).expect("decode --json");
    (o.status.code().unwrap(), j)
}

#[test]
fn sigrok_reads_the_line_and_decode_gives_the_sample_stream() {
    if !tools::require_tool("sigrok-cli") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let (wave, samples) = (dir.path().join("w.vcd"), dir.path().join("s.csv"));
    slotforge()
        .arg("sim")
        .arg(preset())
        .args(["--backend", "rusthdl", "--frames", "1", "--vcd"])
        .arg(&wave)
        .arg("--samples")
        .arg(&samples)
        .assert()
        .code(0);
    let small = dir.path().join("tx.vcd");
    std::fs::write(&small, link_vcd(&std::fs::read_to_string(&wave).unwrap())).unwrap();
    let bytes = sigrok_bytes(&small);
    let cap = dir.path().join("cap.bin");
    std::fs::write(&cap, &bytes).unwrap();

    // The run ends inside slice 9's packet (its trailer follows at the next
    // frame's first cycle): every other packet decodes clean, and the one
    // still in flight is counted as such, not as a loss (exit 0).
    let out = dir.path().join("out.csv");
    let (code, j) = decode_json(&preset(), &cap, &out);
    assert_eq!(code, 0, "{j}");
    assert_eq!(j["ok"], true, "{j}");
    assert!(j["in_flight_bytes"].as_u64().unwrap() > 0, "{j}");
    for k in [
        "crc_errors",
        "lost_packets",
        "resyncs",
        "overflows",
        "skipped_bytes",
    ] {
        assert_eq!(j[k], 0, "{k}: {j}");
    }
    assert_eq!(j["packets"], 9, "{j}");
    let dec = rows(&std::fs::read_to_string(&out).unwrap());
    let sim = rows(&std::fs::read_to_string(&samples).unwrap());
    assert!(
        dec.len() > 300 && dec.len() < sim.len(),
        "{} of {}",
        dec.len(),
        sim.len()
    );
    for (k, (d, s)) in dec.iter().zip(&sim).enumerate() {
        // decode: frame,slice,channel,value,sampled_s;
        // sim: cycle,sampled_s,channel,value, cycle the strobe's
        assert_eq!((&d[2], &d[3], &d[4]), (&s[2], &s[3], &s[1]), "sample {k}");
        let (instant, strobe): (f64, f64) = (d[4].parse().unwrap(), s[0].parse().unwrap());
        let lag = strobe / 48e6 - instant;
        assert!(
            lag > 0.0 && lag < 33.4e-6,
            "sample {k}: sampled {instant}, strobe at cycle {strobe}"
        );
    }

    // The same bytes on stdin, rows to stdout as packets complete.
    let piped = slotforge()
        .arg("decode")
        .arg(preset())
        .args(["-", "-o", "-"])
        .write_stdin(bytes.clone())
        .output()
        .unwrap();
    assert_eq!(piped.status.code(), Some(0));
    assert_eq!(piped.stdout, std::fs::read(&out).unwrap());

    // Garbage first, a flipped bit in a code (packet 3), a dropped byte
    // (packet 6): counted, never hidden.
    let starts: Vec<usize> = (0..bytes.len())
        .step_by(4)
        .filter(|&i| bytes[i] == 0xA5)
        .collect();
    assert!(starts.len() >= 9, "a header per slice: {starts:?}");
    let flip = starts[3] + 4 + 3; // the low byte of packet 3's first record
    let drop = starts[6] + 5;
    let mut bad = vec![0x00, 0xA5, 0x13, 0x5A, 0xFF];
    for (i, &b) in bytes.iter().enumerate() {
        if i == flip {
            bad.push(b ^ 0x01);
        } else if i != drop {
            bad.push(b);
        }
    }
    let cap2 = dir.path().join("bad.bin");
    std::fs::write(&cap2, &bad).unwrap();
    let out2 = dir.path().join("bad.csv");
    let (code, j) = decode_json(&preset(), &cap2, &out2);
    assert_eq!(code, 1);
    assert!(j["crc_errors"].as_u64().unwrap() >= 1, "{j}");
    assert_eq!(j["lost_packets"], 2, "{j}");
    assert_eq!(j["packets"], 7, "{j}");
    assert!(j["skipped_bytes"].as_u64().unwrap() >= 5, "{j}");
    let kept = rows(&std::fs::read_to_string(&out2).unwrap());
    assert!(kept.len() < dec.len() && kept.len() > 200, "{}", kept.len());
    assert!(
        kept.iter().all(|r| dec.contains(r)),
        "only good packets' samples"
    );
}

#[test]
fn a_slow_line_is_refused_with_the_minimum_baud_and_bad_links_are_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(preset()).unwrap();
    let slow = dir.path().join("slow.toml");
    std::fs::write(&slow, text.replace("baud = 3_000_000", "baud = 1_000_000")).unwrap();
    let o = slotforge().arg("audit").arg(&slow).output().unwrap();
    assert_eq!(o.status.code(), Some(1));
    let t = String::from_utf8_lossy(&o.stdout);
    assert!(
        t.contains("the minimum baud that carries this mix is 1500000"),
        "{t}"
    );
    // file, line, column and key of the refused baud, on stderr, as the
    // parser names a bad key; every command that would run or build the
    // link refuses it before it starts (exit 1, infeasible), the same way
    let refusal = format!(
        "{}:326:8: link.baud: 1476 bytes per frame need 708480 cycles of a 1000000-baud line",
        slow.display()
    );
    // the report names the file with the line, text and JSON alike
    assert!(t.contains(&refusal), "{t}");
    let j = slotforge()
        .arg("audit")
        .arg(&slow)
        .arg("--json")
        .output()
        .unwrap();
    let j: serde_json::Value = serde_json::from_slice(&j.stdout).unwrap();
    assert!(
        j["errors"]
            .as_array()
            .unwrap()
            .iter()
            .any(|x| x.as_str().unwrap().starts_with(&refusal)),
        "{j}"
    );
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.contains(&refusal) && e.contains("the minimum baud that carries this mix is 1500000"),
        "{e}"
    );
    let v = dir.path().join("v");
    let b = dir.path().join("b");
    let pr = dir.path().join("prove-out");
    let vcd = dir.path().join("none.vcd");
    for args in [
        vec!["sim", "--frames", "1"],
        vec!["sim", "--frames", "1", "--backend", "rusthdl"],
        vec!["verilog", "-o", v.to_str().unwrap()],
        vec!["check", vcd.to_str().unwrap()],
        vec!["faults", "--false-alarm-mixes", "0"],
        vec!["build", "-o", b.to_str().unwrap()],
        vec!["prove", "-o", pr.to_str().unwrap()],
    ] {
        let o = slotforge()
            .arg(args[0])
            .arg(&slow)
            .args(&args[1..])
            .output()
            .unwrap();
        let e = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {e}");
        assert!(
            e.starts_with(&format!("error: {refusal}"))
                && e.contains("the minimum baud that carries this mix is 1500000")
                && e.lines().count() == 1,
            "{args:?}: {e}"
        );
    }
    assert!(
        !v.exists() && !b.exists() && !pr.exists(),
        "nothing written"
    );

    let odd = dir.path().join("odd.toml");
    std::fs::write(&odd, text.replace("baud = 3_000_000", "baud = 2_900_000")).unwrap();
    let o = slotforge().arg("audit").arg(&odd).output().unwrap();
    assert_eq!(o.status.code(), Some(2));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("link.baud") && e.contains(":326:"), "{e}");

    // every new key's bad value: file, line, column and key, exit 2
    for (from, to, key, words) in [
        (
            "kind = \"uart\"",
            "kind = \"serial\"",
            "link.kind",
            "unknown link kind `serial`",
        ),
        (
            "baud = 3_000_000",
            "baud = 0",
            "link.baud",
            "must be positive, got 0",
        ),
        (
            "baud = 3_000_000",
            "baud = 3_000_000\nparity = \"odd-ish\"",
            "link.parity",
            "unknown parity `odd-ish`",
        ),
        (
            "baud = 3_000_000",
            "baud = 3_000_000\nstop_bits = 3",
            "link.stop_bits",
            "3 stop bits: 1 or 2",
        ),
        (
            "kind = \"uart\"\nbaud = 3_000_000",
            "kind = \"axis\"\ntlast = \"sometimes\"",
            "link.tlast",
            "unknown tlast `sometimes` (\"slice\" or \"frame\")",
        ),
        (
            "kind = \"uart\"\nbaud = 3_000_000",
            "kind = \"axis\"\nbaud = 3_000_000",
            "link.baud",
            "an AXI4-Stream link has no baud",
        ),
        (
            "kind = \"uart\"\nbaud = 3_000_000",
            "kind = \"axis\"\nready_within = 0",
            "link.ready_within",
            "must be positive, got 0",
        ),
    ] {
        assert!(text.contains(from), "{from}");
        let bad = dir.path().join("bad.toml");
        std::fs::write(&bad, text.replace(from, to)).unwrap();
        let o = slotforge().arg("audit").arg(&bad).output().unwrap();
        let e = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{to}: {e}");
        // the key's line in the edited file
        let first = text[..text.find(from).unwrap()].lines().count() + 1;
        let key_at = to.lines().position(|l| l.starts_with(&key[5..]));
        let line = first + key_at.unwrap();
        let at = format!("bad.toml:{line}:");
        assert!(
            e.contains(&at) && e.contains(&format!(": {key}: {words}")),
            "{to}: {e}"
        );
        assert!(!e.contains("panicked"), "{e}");
    }

    let o = slotforge()
        .arg("decode")
        .arg(root().join("mixes/eskin34.toml"))
        .arg(&odd)
        .args(["-o", "-"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("has no [link]"));
}

/// `check --no-model` judges an AXI4-Stream run's beats from its VCD: a
/// `sim` behind the worst-case slave passes; the same VCD with `tlast`
/// never raised fails on `axis-tlast` (exit 1), the model off.
#[test]
fn check_without_the_model_judges_the_axis_beats_of_a_vcd() {
    let dir = tempfile::tempdir().unwrap();
    let tiny = root().join("testkit/mixes/tiny.toml");
    let text =
        std::fs::read_to_string(tiny).unwrap() + "\n[link]\nkind = \"axis\"\nready_within = 8\n";
    let mix = dir.path().join("tiny-axis.toml");
    std::fs::write(&mix, text).unwrap();
    let vcd = dir.path().join("a.vcd");
    slotforge()
        .arg("sim")
        .arg(&mix)
        .args(["--frames", "2", "--tready", "worst", "--vcd"])
        .arg(&vcd)
        .assert()
        .code(0);
    let check = |vcd: &Path| {
        let o = slotforge()
            .arg("check")
            .arg(&mix)
            .arg(vcd)
            .args(["--no-model", "--json"])
            .output()
            .unwrap();
        let out = String::from_utf8_lossy(&o.stdout).to_string();
        (o.status.code(), out)
    };
    let (code, out) = check(&vcd);
    assert_eq!(code, Some(0), "{out}");
    let src = std::fs::read_to_string(&vcd).unwrap();
    let id = src
        .lines()
        .find(|l| l.starts_with("$var") && l.split_whitespace().nth(4) == Some("m_axis_tlast"))
        .and_then(|l| l.split_whitespace().nth(3))
        .expect("m_axis_tlast in the VCD")
        .to_string();
    let body = src.find("$enddefinitions").unwrap();
    let cut: String = src[body..]
        .lines()
        .filter(|l| *l != format!("1{id}"))
        .map(|l| format!("{l}\n"))
        .collect();
    let bad = dir.path().join("no-tlast.vcd");
    std::fs::write(&bad, format!("{}{cut}", &src[..body])).unwrap();
    let (code, out) = check(&bad);
    assert_eq!(code, Some(1), "{out}");
    let r: serde_json::Value = serde_json::from_str(&out).unwrap();
    let rules: Vec<&str> = r["violations"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v["rule"].as_str().unwrap())
        .collect();
    assert!(
        !rules.is_empty() && rules.iter().all(|&x| x == "axis-tlast"),
        "{rules:?}"
    );
}
