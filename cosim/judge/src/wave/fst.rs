//! FST waveforms (Verilator's `--trace-fst`, GTKWave's `vcd2fst`), read
//! through the `wellen` crate and handed to the one VCD reader as VCD text;
//! and written (`sim --fst`, golden FST windows) from the VCD the run
//! wrote, through `fst-writer` (by wellen's author): no external tool.
//!
//! Why transcode rather than read FST natively: every rule of the VCD reader (`read.rs`)
//! (scope detection, vector extension, edges, x/z, inferred clocks, mid-run
//! lock) then holds for FST without a second copy.  The VCD goes to a
//! temporary file streamed change by change (wellen streams FST blocks), so
//! memory stays flat in the file size.  `wellen` may panic on a malformed
//! file: that is caught and reported as a bad
//! file.

use std::fmt::Write as _;
use std::io::{BufWriter, Write};
use std::path::Path;

use wellen::{FileFormat, Hierarchy, LoadOptions, ScopeRef, TimescaleUnit};

use crate::wave::write::id_code;

/// Whether the file is an FST (by its contents, not its name).  A file that
/// starts with text is a VCD (or not a waveform) and is left to the VCD
/// reader, which names what is wrong with it.
pub fn is_fst(path: &Path) -> bool {
    use std::io::Read;
    let Ok(f) = std::fs::File::open(path) else {
        return false;
    };
    let mut rd = std::io::BufReader::new(f);
    let mut first = [0u8; 1];
    if rd.read_exact(&mut first).is_err()
        || first[0].is_ascii_graphic()
        || first[0].is_ascii_whitespace()
    {
        return false;
    }
    let _ = std::io::Seek::rewind(&mut rd);
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        wellen::viewers::detect_file_format(&mut rd)
    }))
    .map(|f| f == FileFormat::Fst)
    .unwrap_or(false)
}

/// Writes the FST at `path` as VCD text to `out`.  Errors are messages
/// naming the file.
pub fn to_vcd(path: &Path, out: &mut dyn Write) -> Result<(), String> {
    let p = path.to_path_buf();
    let mut w = BufWriter::with_capacity(1 << 20, out);
    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| transcode(&p, &mut w)));
    match r {
        Ok(r) => r?,
        Err(_) => {
            return Err(format!(
                "{}: malformed FST (the wellen reader failed on it)",
                path.display()
            ))
        }
    }
    w.flush()
        .map_err(|e| format!("{}: writing its VCD: {e}", path.display()))
}

fn transcode(path: &Path, w: &mut dyn Write) -> Result<(), String> {
    let bad = |e: String| format!("{}: cannot read FST: {e}", path.display());
    let opts = LoadOptions {
        multi_thread: false,
        remove_scopes_with_empty_name: false,
    };
    let mut wave = wellen::stream::read_from_file(path, &opts).map_err(|e| bad(e.to_string()))?;
    let io = |e: std::io::Error| format!("{}: writing its VCD: {e}", path.display());
    let h = wave.hierarchy();
    let mut head = String::new();
    let ts = h
        .timescale()
        .and_then(|t| Some((t.factor, unit_name(t.unit)?)))
        .unwrap_or((1, "s"));
    let _ = writeln!(head, "$timescale {}{} $end", ts.0, ts.1);
    for s in h.scopes() {
        scope(h, s, &mut head);
    }
    head.push_str("$enddefinitions $end\n");
    w.write_all(head.as_bytes()).map_err(io)?;
    let mut time = None;
    let mut line = String::new();
    let r = wave.stream_changes(wellen::stream::Filter::all(), |t, sig, val| {
        line.clear();
        if time != Some(t) {
            let _ = writeln!(line, "#{t}");
            time = Some(t);
        }
        match val.to_bit_string() {
            Some(bits) => {
                let _ = writeln!(line, "b{bits} {}", id_code(sig.index()));
            }
            // Reals, strings and events are not ports of slotforge_top.
            None => return Ok(()),
        }
        w.write_all(line.as_bytes())
    });
    r.map_err(|e| match e {
        wellen::stream::StreamError::Wellen(e) => bad(e.to_string()),
        wellen::stream::StreamError::Callback(e) => io(e),
    })
}

fn scope(h: &Hierarchy, s: ScopeRef, out: &mut String) {
    let sc = &h[s];
    let _ = writeln!(out, "$scope module {} $end", sc.name(h));
    for v in sc.vars(h) {
        let v = &h[v];
        let Some(width) = v.length(h) else { continue };
        let range = match v.index() {
            Some(i) if width > 1 || i.msb() != i.lsb() || i.msb() != 0 => {
                format!(" [{}:{}]", i.msb(), i.lsb())
            }
            _ => String::new(),
        };
        let _ = writeln!(
            out,
            "$var wire {width} {} {}{range} $end",
            id_code(v.signal_ref().index()),
            v.name(h)
        );
    }
    for c in sc.scopes(h) {
        scope(h, c, out);
    }
    out.push_str("$upscope $end\n");
}

fn unit_name(u: TimescaleUnit) -> Option<&'static str> {
    Some(match u {
        TimescaleUnit::ZeptoSeconds => "zs",
        TimescaleUnit::AttoSeconds => "as",
        TimescaleUnit::FemtoSeconds => "fs",
        TimescaleUnit::PicoSeconds => "ps",
        TimescaleUnit::NanoSeconds => "ns",
        TimescaleUnit::MicroSeconds => "us",
        TimescaleUnit::MilliSeconds => "ms",
        TimescaleUnit::Seconds => "s",
        TimescaleUnit::Unknown => return None,
    })
}

/// Writes the VCD at `vcd` as an FST at `fst`: wellen streams the VCD's
/// changes, `fst-writer` writes them (flushed every few MB, so memory
/// stays flat).  The same VCD gives the same bytes (no date is written).
/// Errors are messages naming the file.
pub fn from_vcd(vcd: &Path, fst: &Path) -> Result<(), String> {
    let v = vcd.to_path_buf();
    let f = fst.to_path_buf();
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| write_fst(&v, &f))).unwrap_or_else(
        |_| {
            Err(format!(
                "{}: the wellen reader failed on it while writing {}",
                vcd.display(),
                fst.display()
            ))
        },
    )
}

fn write_fst(vcd: &Path, fst: &Path) -> Result<(), String> {
    use fst_writer::{
        FstFileType, FstInfo, FstScopeType, FstSignalType, FstVarDirection, FstVarType,
    };
    let bad = |e: String| format!("{}: cannot read VCD: {e}", vcd.display());
    let out = |e: fst_writer::FstWriteError| format!("{}: writing FST: {e}", fst.display());
    let opts = LoadOptions {
        multi_thread: false,
        remove_scopes_with_empty_name: false,
    };
    let mut wave = wellen::stream::read_from_file(vcd, &opts).map_err(|e| bad(e.to_string()))?;
    let h = wave.hierarchy();
    let exponent = h
        .timescale()
        .and_then(|t| Some(unit_exponent(t.unit)? + (t.factor as f64).log10().round() as i8))
        .unwrap_or(0);
    let info = FstInfo {
        start_time: 0,
        timescale_exponent: exponent,
        version: "slotforge".into(),
        date: String::new(),
        file_type: FstFileType::Verilog,
    };
    let mut head = fst_writer::open_fst(fst, &info).map_err(out)?;
    // wellen's signal index -> the FST's id (a signal under several names is one id)
    let mut ids: Vec<Option<fst_writer::FstSignalId>> = Vec::new();
    fn walk<W: std::io::Write + std::io::Seek>(
        h: &Hierarchy,
        s: ScopeRef,
        head: &mut fst_writer::FstHeaderWriter<W>,
        ids: &mut Vec<Option<fst_writer::FstSignalId>>,
    ) -> Result<(), fst_writer::FstWriteError> {
        let sc = &h[s];
        head.scope(sc.name(h), "", FstScopeType::Module)?;
        for v in sc.vars(h) {
            let v = &h[v];
            let Some(width) = v.length(h) else { continue };
            let k = v.signal_ref().index();
            if ids.len() <= k {
                ids.resize(k + 1, None);
            }
            let name = match v.index() {
                Some(i) if width > 1 || i.msb() != i.lsb() || i.msb() != 0 => {
                    format!("{} [{}:{}]", v.name(h), i.msb(), i.lsb())
                }
                _ => v.name(h).to_string(),
            };
            let id = head.var(
                name,
                FstSignalType::bit_vec(width),
                FstVarType::Wire,
                FstVarDirection::Implicit,
                ids[k],
            )?;
            ids[k] = Some(id);
        }
        for c in sc.scopes(h) {
            walk(h, c, head, ids)?;
        }
        head.up_scope()
    }
    for s in h.scopes() {
        walk(h, s, &mut head, &mut ids).map_err(out)?;
    }
    let mut body = head.finish().map_err(out)?;
    let mut time = None;
    let r = wave.stream_changes(
        wellen::stream::Filter::all(),
        |t, sig, val| -> std::io::Result<()> {
            let io = |e: fst_writer::FstWriteError| std::io::Error::other(e.to_string());
            let Some(Some(id)) = ids.get(sig.index()) else {
                return Ok(());
            };
            let Some(bits) = val.to_bit_string() else {
                return Ok(()); // reals and strings are not ports of slotforge_top
            };
            if time != Some(t) {
                body.time_change(t).map_err(io)?;
                time = Some(t);
            }
            body.signal_change(*id, bits.as_bytes()).map_err(io)?;
            if body.size() > 8 << 20 {
                body.flush().map_err(io)?;
            }
            Ok(())
        },
    );
    r.map_err(|e| match e {
        wellen::stream::StreamError::Wellen(e) => bad(e.to_string()),
        wellen::stream::StreamError::Callback(e) => format!("{}: writing FST: {e}", fst.display()),
    })?;
    body.finish().map_err(out)?;
    Ok(())
}

/// The power of ten of a timescale unit.
fn unit_exponent(u: TimescaleUnit) -> Option<i8> {
    Some(match u {
        TimescaleUnit::ZeptoSeconds => -21,
        TimescaleUnit::AttoSeconds => -18,
        TimescaleUnit::FemtoSeconds => -15,
        TimescaleUnit::PicoSeconds => -12,
        TimescaleUnit::NanoSeconds => -9,
        TimescaleUnit::MicroSeconds => -6,
        TimescaleUnit::MilliSeconds => -3,
        TimescaleUnit::Seconds => 0,
        TimescaleUnit::Unknown => return None,
    })
}
