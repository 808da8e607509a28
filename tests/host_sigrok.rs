//! `slotforge sigrok`: the protocol decoder it writes, run by sigrok-cli
//! (Debian's libsigrokdecode, found through `SIGROKDECODE_DIR`) stacked on
//! sigrok's own `uart` decoder over `link_tx` of a simulation's VCD,
//! annotates exactly the records `decode` reads from the same run's
//! `--link-bytes`: each channel's name and code, in order, one good
//! trailer per packet.  Mixes it cannot serve are refused (exit 2).

use std::path::Path;
use std::process::Command as Process;

use crate::common_cli::{refused, root, slotforge, tiny};
use crate::tools;

/// `link_tx` alone, times in ns: sigrok's VCD input reads 1-bit signals at
/// the file's timescale (slotforge's is 1 ps: a sample per ps), so it gets
/// the line it decodes at a rate it can take.
fn link_tx_vcd(src: &str) -> String {
    let mut id = None;
    let mut scale_ps = None;
    let mut out = String::from("$timescale 1ns $end\n$scope module top $end\n");
    let mut t = 0u128;
    let mut body = false;
    for l in src.lines() {
        let w: Vec<&str> = l.split_whitespace().collect();
        match w.as_slice() {
            ["$timescale", v, "$end"] => scale_ps = Some(unit_ps(v)),
            ["$timescale"] => {}
            ["$var", _, "1", code, "link_tx", ..] => id = Some(code.to_string()),
            ["$enddefinitions", ..] => {
                let code = id.as_deref().expect("the VCD has link_tx");
                out += &format!(
                    "$var wire 1 {code} link_tx $end\n$upscope $end\n$enddefinitions $end\n"
                );
                body = true;
            }
            [stamp] if body && stamp.starts_with('#') => {
                t = stamp[1..].parse::<u128>().unwrap() * scale_ps.expect("a timescale");
            }
            [v] if body && v.len() > 1 && id.as_deref() == Some(&v[1..]) => {
                out += &format!("#{}\n{}{}\n", (t + 500) / 1000, &v[..1], &v[1..]);
            }
            _ => {}
        }
    }
    out
}

/// `1ps`, `1 ps`'s number, `10ns` ... in picoseconds.
fn unit_ps(v: &str) -> u128 {
    let n: u128 = v.trim_end_matches(char::is_alphabetic).parse().unwrap_or(1);
    n * match v.trim_start_matches(char::is_numeric) {
        "fs" => 0,
        "ps" => 1,
        "ns" => 1_000,
        "us" => 1_000_000,
        other => panic!("timescale unit {other}"),
    }
}

/// `decode`'s rows as `name: code`.
fn decoded(mix: &Path, bytes: &Path) -> Vec<String> {
    let out = slotforge()
        .arg("decode")
        .arg(mix)
        .arg(bytes)
        .args(["-o", "-"])
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let csv = String::from_utf8(out.stdout).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let (c, v) = (
        header.iter().position(|h| *h == "channel").unwrap(),
        header.iter().position(|h| *h == "value").unwrap(),
    );
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            format!("{}: {}", f[c], f[v])
        })
        .collect()
}

/// The decoder for `mix` written, sigrok-cli run on the VCD of `frames`
/// frames; (its annotations as `class: text`, decode's records).
fn sigrok_on_a_run(
    mix: &Path,
    backend: &str,
    frames: u64,
    dir: &Path,
) -> (Vec<(String, String)>, Vec<String>) {
    let decoders = dir.join("decoders");
    let o = slotforge()
        .arg("sigrok")
        .arg(mix)
        .arg("-o")
        .arg(&decoders)
        .output()
        .unwrap();
    let said = String::from_utf8_lossy(&o.stdout).to_string();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{said}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let id = said
        .split('`')
        .nth(1)
        .expect("the decoder's id")
        .to_string();
    let uart = said
        .split("uart:rx=LINE:")
        .nth(1)
        .unwrap()
        .split(',')
        .next()
        .unwrap()
        .to_string();
    for f in ["__init__.py", "pd.py"] {
        assert!(decoders.join(&id).join(f).is_file(), "{id}/{f}");
    }
    let (vcd, bytes) = (dir.join("run.vcd"), dir.join("line.bin"));
    slotforge()
        .arg("sim")
        .arg(mix)
        .args([
            "--backend",
            backend,
            "--frames",
            &frames.to_string(),
            "--quiet",
        ])
        .args(["--to", &frames.to_string(), "--vcd"])
        .arg(&vcd)
        .arg("--link-bytes")
        .arg(&bytes)
        .assert()
        .code(0);
    let line = dir.join("link_tx.vcd");
    std::fs::write(&line, link_tx_vcd(&std::fs::read_to_string(&vcd).unwrap())).unwrap();
    let o = Process::new("sigrok-cli")
        .env("SIGROKDECODE_DIR", &decoders)
        .args(["-I", "vcd", "-i"])
        .arg(&line)
        .args(["-P", &format!("uart:rx=link_tx:{uart},{id}"), "-A", &id])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success() && !err.contains("Traceback"), "{err}");
    let anns = String::from_utf8(o.stdout)
        .unwrap()
        .lines()
        .filter_map(|l| {
            // `<id>-1: <text>`; the class told by its text (docs/host.md)
            let text = l.strip_prefix(&format!("{id}-1: "))?;
            Some((class_of(text).to_string(), text.to_string()))
        })
        .collect();
    (anns, decoded(mix, &bytes))
}

/// An annotation's class, from its text.
fn class_of(text: &str) -> &'static str {
    match text {
        t if t.starts_with("Frame ") => "header",
        t if t.starts_with("Overflows ") && t.ends_with("CRC good") => "trailer",
        t if t.starts_with("Overflows ") => "crc-bad",
        t if t.starts_with("Skipped ") => "skipped",
        _ => "record",
    }
}

/// The annotations of one class, in order.
fn of(anns: &[(String, String)], class: &str) -> Vec<String> {
    anns.iter()
        .filter(|a| a.0 == class)
        .map(|a| a.1.clone())
        .collect()
}

#[test]
fn sigrok_decodes_a_simulated_line_to_decodes_records() {
    if !tools::require_tool("sigrok-cli") || !tools::require_tool("verilator") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    // a UART mix no preset has: its own channels, baud, parity and stop bits
    let unseen = dir.path().join("unseen-uart.toml");
    let text = std::fs::read_to_string(tiny())
        .unwrap()
        .replace("\"tiny\"", "\"unseen-uart\"");
    let link = "\n[link]\nkind = \"uart\"\nbaud = 1_000_000\nparity = \"even\"\nstop_bits = 2\n";
    std::fs::write(&unseen, text + link).unwrap();
    for (mix, backend, frames) in [
        (unseen.as_path(), "verilator", 6),
        (&root().join("mixes/eskin34-uart.toml"), "model", 1),
    ] {
        let (anns, want) = sigrok_on_a_run(mix, backend, frames, dir.path());
        let what = mix.display();
        assert!(want.len() > 20, "{what}: {} rows", want.len());
        assert_eq!(of(&anns, "record"), want, "{what}");
        let packets = of(&anns, "header").len();
        assert!(packets >= frames as usize, "{what}: {packets} packets");
        assert_eq!(
            of(&anns, "trailer"),
            vec!["Overflows 0, CRC good".to_string(); packets]
        );
        assert!(of(&anns, "crc-bad").is_empty(), "{what}");
        assert!(
            of(&anns, "header")[0].starts_with("Frame 0, slice 0"),
            "{anns:?}"
        );
    }
}

#[test]
fn sigrok_refuses_a_mix_without_a_uart() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("d");
    refused(
        &[
            &"sigrok",
            &root().join("mixes/eskin34-axis.toml"),
            &"-o",
            &out,
        ],
        &["eskin34-axis.toml", "link.kind is \"axis\""],
    );
    refused(
        &[&"sigrok", &root().join("mixes/eskin34.toml"), &"-o", &out],
        &["eskin34.toml", "has no [link]"],
    );
    assert!(!out.exists(), "nothing written");
}
