//! `slotforge decode MIX CAPTURE -o OUT.csv [--json]`: the bytes a host
//! received from the link, as samples (`frame,slice,channel,value,sampled_s`;
//! a mix with modes adds `mode`, the name of the packet's frame's mode, whose
//! schedule, and the frame before's, give `sampled_s`).
//!
//! The decoding is `host::Samples` (`link::Decoder`, the packet format's
//! one home, with the sampling instants from the schedule), the decoder the
//! Python package shares; `sampled_s` is written as `sim --samples` writes
//! it (`lut_gen::seconds`), so the two CSVs agree for the same sample.
//! `CAPTURE` may be `-`: stdin is decoded as it arrives and each packet's
//! rows are written when its trailer arrives (with `-o -`, to stdout at once).
//!
//! Exit 0: a clean stream (a packet still in flight when the capture ends
//! included: its bytes are counted, not lost); 1: losses, CRC errors,
//! resyncs, skipped bytes or an overflow the gateware reported (counted,
//! never fatal); 2: bad input.

use std::io::{Read, Write};
use std::path::{Path, PathBuf};

use link::Stats;

#[derive(clap::Args)]
pub struct Args {
    /// The channel-mix file (TOML) with a `[link]`.
    pub mix: PathBuf,
    /// The raw bytes the host received (a serial-port dump, a logic
    /// analyser's decoded bytes, or `sim --link-bytes`), or `-` for stdin.
    pub capture: PathBuf,
    /// The CSV to write, or `-` for stdout.
    #[arg(short, long)]
    pub out: PathBuf,
    /// Print the counts as JSON.
    #[arg(long)]
    pub json: bool,
}

/// The CSV's first line.
pub const HEADER: &str = "frame,slice,channel,value,sampled_s";
/// The CSV's first line for a mix with modes.
pub const HEADER_MODES: &str = "frame,slice,mode,channel,value,sampled_s";

/// The decoder's samples as CSV rows.
struct Rows {
    dec: host::Samples,
    /// A mix with modes: the modes' names (the `mode` column).
    modes: Vec<String>,
    rows: u64,
    got: Vec<host::Sample>,
}

impl Rows {
    /// The rows of the packets `bytes` complete, appended to `out`.
    fn push(&mut self, bytes: &[u8], out: &mut String) {
        use std::fmt::Write as _;
        self.got.clear();
        self.dec.push(bytes, &mut self.got);
        for x in &self.got {
            let mode = match self.modes.is_empty() {
                true => String::new(),
                false => {
                    let name = self.modes.get(x.mode as usize).map_or("", String::as_str);
                    format!("{name},")
                }
            };
            let (name, t) = (self.dec.name(x.channel), self.dec.seconds(x));
            let _ = writeln!(out, "{},{},{mode}{name},{},{t}", x.frame, x.slice, x.value);
            self.rows += 1;
        }
    }
}

/// Where rows go: stdout at once, or a temporary file renamed at the end
/// (an interrupted run leaves no half-written CSV under the user's name).
enum Sink {
    Stdout,
    File {
        tmp: PathBuf,
        path: PathBuf,
        f: std::io::BufWriter<std::fs::File>,
    },
}

impl Sink {
    fn open(path: &Path) -> Result<Sink, String> {
        if path == Path::new("-") {
            return Ok(Sink::Stdout);
        }
        let path = &super::output_file("-o", path)?;
        let name = path.file_name().expect("output_file names a file");
        let tmp = path.with_file_name(format!(".{}.tmp", name.to_string_lossy()));
        let f = std::fs::File::create(&tmp).map_err(|e| {
            format!(
                "{}: cannot write: {}",
                path.display(),
                lut_gen::write_words(&e)
            )
        })?;
        Ok(Sink::File {
            tmp,
            path: path.to_path_buf(),
            f: std::io::BufWriter::new(f),
        })
    }

    fn put(&mut self, text: &str) -> std::io::Result<()> {
        match self {
            Sink::Stdout => {
                let mut o = std::io::stdout().lock();
                o.write_all(text.as_bytes())?;
                o.flush()
            }
            Sink::File { f, .. } => f.write_all(text.as_bytes()),
        }
    }

    fn finish(self) -> Result<(), String> {
        if let Sink::File { tmp, path, mut f } = self {
            super::put_in_place(&tmp, &path, f.flush())?;
        }
        Ok(())
    }
}

pub fn run(a: Args) -> u8 {
    let s = match super::schedule(&a.mix) {
        Ok(s) => s,
        Err(code) => return code,
    };
    let Some(dec) = host::Samples::new(&s) else {
        eprintln!(
            "error: {}: the mix has no [link]: its samples leave on the parallel sample port, there is nothing to decode",
            a.mix.display()
        );
        return 2;
    };
    let mut input: Box<dyn Read> = if a.capture == Path::new("-") {
        Box::new(std::io::stdin().lock())
    } else {
        match std::fs::File::open(&a.capture) {
            Ok(f) => Box::new(f),
            Err(e) => {
                eprintln!(
                    "error: {}: cannot read the capture: {}",
                    a.capture.display(),
                    lut_gen::io_words(&e)
                );
                return 2;
            }
        }
    };
    let mut sink = match Sink::open(&a.out) {
        Ok(k) => k,
        Err(e) => {
            eprintln!("error: {e}");
            return 2;
        }
    };
    let modes: Vec<String> = dec.mode_names().iter().map(|m| m.to_string()).collect();
    let mut text = format!(
        "{}\n",
        if modes.is_empty() {
            HEADER
        } else {
            HEADER_MODES
        }
    );
    let mut rows = Rows {
        dec,
        modes,
        rows: 0,
        got: Vec::new(),
    };
    let mut buf = vec![0u8; 1 << 16];
    loop {
        let n = match input.read(&mut buf) {
            Ok(0) => break,
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => {
                let why = lut_gen::io_words(&e);
                eprintln!("error: {}: reading the capture: {why}", a.capture.display());
                return 2;
            }
        };
        rows.push(&buf[..n], &mut text);
        if !text.is_empty() {
            if let Err(e) = sink.put(&text) {
                let why = lut_gen::write_words(&e);
                eprintln!("error: {}: cannot write: {why}", a.out.display());
                return 2;
            }
            text.clear();
        }
    }
    let st = rows.dec.finish();
    if let Err(e) = sink.finish() {
        eprintln!("error: {e}");
        return 2;
    }
    report(&a, &st, rows.rows);
    if st.clean() {
        0
    } else {
        1
    }
}

fn report(a: &Args, st: &Stats, rows: u64) {
    let json = serde_json::json!({
        "ok": st.clean(),
        "bytes": st.bytes,
        "packets": st.packets,
        "samples": rows,
        "crc_errors": st.crc_errors,
        "lost_packets": st.lost_packets,
        "resyncs": st.resyncs,
        "skipped_bytes": st.skipped_bytes,
        "overflows": st.overflows,
        "in_flight_bytes": st.in_flight,
    });
    if a.json {
        let text = serde_json::to_string_pretty(&json).expect("json") + "\n";
        if a.out == Path::new("-") {
            eprint!("{text}");
        } else {
            print!("{text}");
        }
        return;
    }
    let mut msg = format!(
        "{}: {} bytes, {} packets, {rows} samples",
        a.capture.display(),
        st.bytes,
        st.packets
    );
    if st.clean() {
        msg.push_str(": clean");
    } else {
        msg.push_str(&format!(
            "; {}, {}, {}, {} skipped{}",
            super::counted(st.crc_errors, "CRC error"),
            super::counted(st.lost_packets, "lost packet"),
            super::counted(st.resyncs, "resync"),
            super::counted(st.skipped_bytes, "byte"),
            if st.overflows > 0 {
                format!(
                    ", the gateware's FIFO overflowed {}",
                    super::counted(st.overflows.into(), "time")
                )
            } else {
                String::new()
            },
        ));
    }
    if st.in_flight > 0 {
        msg.push_str(&format!(
            "; {} of a packet still in flight when the capture ends (not a loss)",
            super::counted(st.in_flight, "byte")
        ));
    }
    eprintln!("{msg}");
}
