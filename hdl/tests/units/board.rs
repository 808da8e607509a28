use hdl::for_tests::board_constraints;
use std::path::Path;

use hdl::{stock_board, Board};
use lut_gen::{Constraints, Fpga, Layout};

use crate::common::from_toml as schedule;

/// `(port name, pin)` of each line that places one, in the format's words.
fn placed(format: Constraints, text: &str) -> Vec<(String, String)> {
    let unquote = |w: &str| w.trim_matches(|c| c == '"' || c == ';').to_string();
    text.lines()
        .filter_map(|l| {
            let w: Vec<&str> = l.split_whitespace().collect();
            match (format, w.as_slice()) {
                (Constraints::Pcf, ["set_io", n, p, ..]) => Some((unquote(n), unquote(p))),
                (Constraints::Lpf, ["LOCATE", "COMP", n, "SITE", p, ..]) => {
                    Some((unquote(n), unquote(p)))
                }
                (Constraints::Cst, ["IO_LOC", n, p, ..]) => Some((unquote(n), unquote(p))),
                _ => None,
            }
        })
        .collect()
}

#[test]
fn each_parts_board_places_every_port_bit_once_in_its_format() {
    let mixes = [
        schedule("eskin34.toml", include_str!("../../../mixes/eskin34.toml")),
        schedule(
            "cnvmix2ms.toml",
            include_str!("../../../testkit/mixes/cnvmix2ms.toml"),
        ),
    ];
    for s in &mixes {
        let bits = Layout::new(s).bits();
        for f in Fpga::ALL {
            let b: Board = toml::from_str(stock_board(f)).unwrap();
            assert_eq!((b.fpga, b.name.as_str()), (f, f.board().0));
            let format = f.family().constraints();
            let (file, text) = board_constraints(&b, s, Path::new("board.toml")).unwrap();
            assert_eq!(file, format.file());
            let p = placed(format, &text);
            assert_eq!(p.len(), bits.len(), "{f}: {text}");
            let mut names: Vec<&str> = p.iter().map(|(n, _)| n.as_str()).collect();
            let mut pins: Vec<&str> = p.iter().map(|(_, x)| x.as_str()).collect();
            names.sort();
            names.dedup();
            pins.sort();
            pins.dedup();
            assert_eq!((names.len(), pins.len()), (bits.len(), bits.len()), "{f}");
            for (n, pin) in &p {
                assert!(b.pins.values().chain(&b.pool.pins).any(|x| x == pin));
                if format != Constraints::Pcf {
                    // each port its I/O standard, the pin's bank's
                    let io = b.io_types.get(pin).unwrap_or(&b.io_type);
                    assert!(text.contains(&format!("\"{n}\" IO_TYPE={io};")), "{n}");
                }
            }
            let clk = p.iter().find(|(n, _)| n == "clk").unwrap();
            assert_eq!(Some(&clk.1), b.pins.get("clk"), "{f}");
            if format == Constraints::Lpf {
                let mhz = s.grid.clock_hz as f64 / 1e6;
                assert!(text.contains(&format!("FREQUENCY PORT \"clk\" {mhz} MHZ;")));
            }
        }
    }
}

#[test]
fn a_board_without_a_part_is_an_ice40_one_and_a_bad_part_is_named() {
    let old = "name = \"b\"\ndevice = \"hx8k\"\npackage = \"ct256\"\n";
    let b: Board = toml::from_str(old).unwrap();
    assert_eq!(b.fpga, Fpga::Ice40Hx8k);
    let e = toml::from_str::<Board>(&format!("{old}fpga = \"xc7a35t\"\n")).unwrap_err();
    assert!(e.to_string().contains("xc7a35t"), "{e}");
}

#[test]
fn emit_with_a_board_writes_its_familys_file_only() {
    let s = schedule("eskin34.toml", include_str!("../../../mixes/eskin34.toml"));
    let d = std::env::temp_dir().join(format!("slotforge-board-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    for f in Fpga::ALL {
        let path = d.join(f.board().1);
        std::fs::write(&path, stock_board(f)).unwrap();
        let e = hdl::emit(&s, Some(&path)).unwrap();
        for c in [Constraints::Pcf, Constraints::Lpf, Constraints::Cst] {
            let want = c == f.family().constraints();
            assert_eq!(e.file(c.file()).is_some(), want, "{f} {}", c.file());
        }
    }
    let _ = std::fs::remove_dir_all(&d);
}
