//! Logic-analyser captures for the time-level check (`check.rs`): the map
//! from analyser channels to port bits (`--map D0=adc_cs_n[0],...` or a
//! file of such lines), sigrok-cli's VCD (1-bit channels, its sample rate in
//! a comment), and sigrok session files (`.sr`), which sigrok-cli itself
//! turns into that VCD (the format's own reader, rather than a second one).

use std::path::Path;

use lut_gen::Schedule;
use lut_gen::{Layout, Role, Signal, AXIS_PORTS, LINK_PORTS, PORT_NAMES};

use crate::capture::check::{Capture, Lane, ModePin};

/// Parses `--map`: `CH=PORT[BIT],...` inline, or the path of a file with one
/// `CH = PORT[BIT]` per line (`#` comments).  Errors name the line and field.
pub fn parse_map(spec: &str, s: &Schedule) -> Result<Vec<Lane>, String> {
    // Every inline entry has a `=`: without one, the map is a file's name.
    let (text, file) = if spec.contains('=') {
        (spec.replace(',', "\n"), None)
    } else {
        let t = std::fs::read_to_string(spec)
            .map_err(|e| format!("--map {spec}: {}", lut_gen::io_words(&e)))?;
        (t, Some(spec))
    };
    let layout = Layout::new(s);
    let mut lanes: Vec<Lane> = Vec::new();
    for (n, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let at = |m: String| match file {
            Some(f) => format!("{f}:{}: {m}", n + 1),
            None => format!("--map `{line}`: {m}"),
        };
        let (ch, port) = line
            .split_once('=')
            .ok_or_else(|| at("expected CHANNEL=PORT[BIT], e.g. D0=adc_cs_n[0]".into()))?;
        let (ch, port) = (ch.trim(), port.trim());
        let (name, bit) = match port.split_once('[') {
            Some((nm, rest)) => {
                let b = rest
                    .strip_suffix(']')
                    .and_then(|b| b.trim().parse::<u32>().ok())
                    .ok_or_else(|| at(format!("bit of `{port}` is not a number in [..]")))?;
                (nm.trim(), b)
            }
            None => (port, 0),
        };
        let mode = mode_port(&layout, name, bit).map_err(at)?;
        let (role, link) = match mode {
            Some(_) => (None, None),
            None => lane_port(&layout, name, bit).map_err(at)?,
        };
        if mode.is_some() && lanes.iter().any(|x| x.mode == mode && x.bit == bit) {
            return Err(at(format!("`{name}[{bit}]` is mapped twice")));
        }
        if let Some(l) = link.filter(|_| lanes.iter().any(|x| x.link == link && x.bit == bit)) {
            return Err(at(format!("`{}` is mapped twice", l.name(&layout))));
        }
        if lanes.iter().any(|l| l.channel == ch) {
            return Err(at(format!("channel `{ch}` is mapped twice")));
        }
        lanes.push(Lane {
            channel: ch.to_string(),
            role,
            bit,
            link,
            mode,
        });
    }
    if lanes.is_empty() {
        return Err("--map maps no channel".into());
    }
    if lanes.len() > 64 {
        return Err(format!(
            "--map maps {} channels; at most 64 are checked at once",
            lanes.len()
        ));
    }
    Ok(lanes)
}

/// `name[bit]` when it is a mode port (`mode_sel`, `mode`): the ones this
/// mix has, or a message saying why not.
fn mode_port(layout: &Layout, name: &str, bit: u32) -> Result<Option<ModePin>, String> {
    let Some(k) = lut_gen::MODE_PORTS.iter().position(|p| p.name == name) else {
        return Ok(None);
    };
    if !layout.mode_ports().iter().any(|p| p.name == name) {
        return Err(match layout.mode_bits {
            0 => format!("`{name}`: this mix has no [[mode]]"),
            _ => format!("`{name}`: this mix selects its modes automatically (`select = \"auto\"`): it has `mode` only"),
        });
    }
    if bit >= layout.mode_bits {
        return Err(format!(
            "`{name}` has {} bit(s) in this mix, no bit {bit}",
            layout.mode_bits
        ));
    }
    Ok(Some([ModePin::Sel, ModePin::Mode][k]))
}

/// The port bit `name[bit]` names: a core port's role, or the link's port
/// (`link_tx`, `link_overflow`, `m_axis_*`, the ones this mix's link has).
fn lane_port(
    layout: &Layout,
    name: &str,
    bit: u32,
) -> Result<(Option<Role>, Option<Signal>), String> {
    let widths = layout.port_widths();
    let link_names = || {
        layout
            .link_ports()
            .iter()
            .map(|p| match p.width {
                1 => p.name.to_string(),
                w => format!("{}[{}:0]", p.name, w - 1),
            })
            .collect::<Vec<_>>()
    };
    if LINK_PORTS.iter().chain(&AXIS_PORTS).any(|p| p.name == name) {
        let Some(p) = layout.link_ports().iter().find(|q| q.name == name) else {
            return Err(match (layout.link, layout.axis) {
                (false, _) => format!("`{name}`: this mix has no [link]"),
                (true, axis) => format!(
                    "`{name}`: this mix's link is {}, whose ports are {}",
                    if axis { "AXI4-Stream" } else { "a UART" },
                    link_names().join(", ")
                ),
            });
        };
        if bit >= p.width {
            return Err(format!("`{name}` has {} bit(s), no bit {bit}", p.width));
        }
        return Ok((None, Some(p.signal)));
    }
    let Some(pi) = PORT_NAMES.iter().position(|p| *p == name) else {
        let mut names: Vec<String> = PORT_NAMES.iter().map(|p| p.to_string()).collect();
        names.extend(link_names());
        return Err(format!(
            "`{name}` is not a port of slotforge_top ({})",
            names.join(", ")
        ));
    };
    if bit >= widths[pi] {
        return Err(format!(
            "`{name}` has {} bit(s) in this mix, no bit {bit}",
            widths[pi]
        ));
    }
    Ok((Some(lut_gen::PORTS[pi].role), None))
}

/// Reads a capture: sigrok-cli's VCD, or a `.sr` session through sigrok-cli.
pub fn read(path: &Path, lanes: Vec<Lane>) -> Result<Capture, String> {
    read_progress(path, lanes, &|_, _| {})
}

/// [`read`], telling `progress(bytes parsed, bytes in all)` of the VCD as
/// it goes: an analyser's capture runs to hundreds of MB.
pub fn read_progress(
    path: &Path,
    lanes: Vec<Lane>,
    progress: &dyn Fn(u64, u64),
) -> Result<Capture, String> {
    let mut head = [0u8; 2];
    let is_zip = std::fs::File::open(path)
        .and_then(|mut f| std::io::Read::read_exact(&mut f, &mut head))
        .map(|_| &head == b"PK")
        .unwrap_or(false);
    if !is_zip {
        let text = std::fs::read_to_string(path)
            .map_err(|e| format!("{}: {}", path.display(), lut_gen::io_words(&e)))?;
        return parse_vcd(&text, path, lanes, progress);
    }
    let vcd = sigrok_to_vcd(path)?;
    let text = std::fs::read_to_string(&vcd).map_err(|e| format!("{}: {e}", path.display()))?;
    parse_vcd(&text, path, lanes, progress)
}

/// Longest a `.sr` conversion may take (a capture of hundreds of MB takes
/// tens of seconds).
const SIGROK_LIMIT: std::time::Duration = std::time::Duration::from_secs(900);

/// A `.sr` session converted to a VCD by sigrok-cli (through the one tool
/// runner, with a time limit), in a temporary directory kept with it.
fn sigrok_to_vcd(path: &Path) -> Result<TempVcd, String> {
    let at = std::path::absolute(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let dir = tempfile::tempdir().map_err(|e| format!("temporary directory: {e}"))?;
    let vcd = dir.path().join("capture.vcd");
    let (input, output) = (at.to_string_lossy(), vcd.to_string_lossy());
    let args = ["-i", input.as_ref(), "-O", "vcd", "-o", output.as_ref()];
    let out = crate::tools::run("sigrok-cli", &args, dir.path(), SIGROK_LIMIT).map_err(|e| {
        match e {
            crate::tools::ToolError::Missing(_) => format!(
                "{}: a sigrok session (.sr) is read through sigrok-cli, which is not installed (`make tools` installs it)",
                path.display()
            ),
            other => format!("{}: {other}", path.display()),
        }
    })?;
    if !out.success {
        return Err(format!(
            "{}: sigrok-cli cannot read it: {}",
            path.display(),
            out.stderr.trim()
        ));
    }
    Ok(TempVcd { _dir: dir, vcd })
}

/// A converted VCD and the temporary directory that holds it.
struct TempVcd {
    _dir: tempfile::TempDir,
    vcd: std::path::PathBuf,
}

impl AsRef<Path> for TempVcd {
    fn as_ref(&self) -> &Path {
        &self.vcd
    }
}

fn unit_ps(u: &str) -> Option<f64> {
    Some(match u {
        "s" => 1e12,
        "ms" => 1e9,
        "us" => 1e6,
        "ns" => 1e3,
        "ps" => 1.0,
        "fs" => 1e-3,
        _ => return None,
    })
}

/// sigrok-cli's VCD: 1-bit `$var`s named by the analyser's channels, the
/// sample rate in `$comment ... at 24 MHz $end`.
fn parse_vcd(
    text: &str,
    path: &Path,
    lanes: Vec<Lane>,
    progress: &dyn Fn(u64, u64),
) -> Result<Capture, String> {
    let total = text.len() as u64;
    // told at every 256 kB, not every line: a call per line would cost more
    // than the parsing
    let step = 1u64 << 18;
    let next = std::cell::Cell::new(step);
    let told = |line: &str| {
        let at = (line.as_ptr() as usize - text.as_ptr() as usize) as u64;
        if at >= next.get() {
            next.set(at + step);
            progress(at, total);
        }
    };
    let mut toks = text
        .lines()
        .enumerate()
        .inspect(|(_, l)| told(l))
        .flat_map(|(n, l)| l.split_whitespace().map(move |w| (n + 1, w)));
    let head = read_header(&mut toks, path, &lanes)?;
    let steps = read_body(&mut toks, path, &head)?;
    progress(total, total);
    // Without the rate comment, the smallest step between timestamps.
    // With the rate known, one timescale unit is added: sigrok rounds each
    // sample's time to it.
    let period_ps = match head.rate_hz {
        Some(r) => (1e12 / r).round() as u64 + head.scale_ps.ceil() as u64,
        None => steps
            .windows(2)
            .map(|w| w[1].0 - w[0].0)
            .filter(|d| *d > 0)
            .min()
            .ok_or_else(|| format!("{}: no sample rate and too few samples", path.display()))?,
    };
    Ok(Capture {
        lanes,
        period_ps,
        steps,
    })
}

/// An error at line `line` of the capture.
fn at_line(path: &Path, line: usize, m: String) -> String {
    format!("{}:{line}: {m}", path.display())
}

/// What the capture's header declares.
struct CaptureHeader {
    /// Identifier code -> lane, for the channels the map names.
    ids: Vec<(String, usize)>,
    scale_ps: f64,
    rate_hz: Option<f64>,
}

/// The header's tokens (`(line, token)`), up to `$enddefinitions`: every
/// channel the map names must be declared.
fn read_header<'t>(
    toks: &mut impl Iterator<Item = (usize, &'t str)>,
    path: &Path,
    lanes: &[Lane],
) -> Result<CaptureHeader, String> {
    let mut head = CaptureHeader {
        ids: Vec::new(),
        scale_ps: 1.0,
        rate_hz: None,
    };
    let mut names = Vec::new();
    while let Some((n, w)) = toks.next() {
        let mut group = vec![];
        if w.starts_with('$') && w != "$end" {
            for (_, x) in toks.by_ref() {
                if x == "$end" {
                    break;
                }
                group.push(x);
            }
        }
        match w {
            "$timescale" => {
                let s: String = group.concat();
                let i = s.find(|c: char| !c.is_ascii_digit()).unwrap_or(s.len());
                let k: f64 = s[..i].parse().unwrap_or(1.0);
                head.scale_ps = k * unit_ps(&s[i..])
                    .ok_or_else(|| at_line(path, n, format!("timescale `{s}`")))?;
            }
            "$comment" => {
                if let Some(i) = group.iter().position(|x| *x == "at") {
                    if let (Some(v), Some(u)) = (group.get(i + 1), group.get(i + 2)) {
                        let m = match *u {
                            "Hz" => 1.0,
                            "kHz" => 1e3,
                            "MHz" => 1e6,
                            "GHz" => 1e9,
                            _ => 0.0,
                        };
                        head.rate_hz = v.parse::<f64>().ok().map(|v| v * m).filter(|r| *r > 0.0);
                    }
                }
            }
            "$var" => {
                if group.len() < 4 {
                    return Err(at_line(
                        path,
                        n,
                        "$var needs type, width, code and name".into(),
                    ));
                }
                let name = group[3].to_string();
                names.push(name.clone());
                if let Some(li) = lanes.iter().position(|l| l.channel == name) {
                    head.ids.push((group[2].to_string(), li));
                }
            }
            "$enddefinitions" => {
                let missing: Vec<&str> = lanes
                    .iter()
                    .filter(|l| !names.contains(&l.channel))
                    .map(|l| l.channel.as_str())
                    .collect();
                if !missing.is_empty() {
                    return Err(format!(
                        "{}: --map names channel(s) {} that the capture does not have (it has {})",
                        path.display(),
                        missing.join(", "),
                        names.join(", ")
                    ));
                }
                return Ok(head);
            }
            _ => {}
        }
    }
    Ok(head)
}

/// The body's tokens: the mapped lanes' levels as (time in ps, bits) at
/// every timestamp where they changed, and at the end.
fn read_body<'t>(
    toks: &mut impl Iterator<Item = (usize, &'t str)>,
    path: &Path,
    head: &CaptureHeader,
) -> Result<Vec<(u64, u64)>, String> {
    let mut steps: Vec<(u64, u64)> = Vec::new();
    let mut cur = 0u64;
    let mut t = 0u64;
    while let Some((n, w)) = toks.next() {
        if let Some(ts) = w.strip_prefix('#') {
            let nt: u64 = ts
                .parse()
                .map_err(|_| at_line(path, n, format!("bad timestamp `{w}`")))?;
            if nt < t {
                return Err(at_line(
                    path,
                    n,
                    format!("time goes backwards from {t} to {nt}"),
                ));
            }
            if steps.last().map(|s| s.1) != Some(cur) || steps.is_empty() {
                steps.push(((t as f64 * head.scale_ps) as u64, cur));
            }
            t = nt;
            continue;
        }
        if w.starts_with('$') {
            continue;
        }
        let (val, code) = match w.as_bytes()[0] {
            b'0' | b'1' | b'x' | b'z' | b'X' | b'Z' => (w.as_bytes()[0], &w[1..]),
            b'b' | b'B' => {
                let c = toks.next().map(|x| x.1).unwrap_or("");
                (*w.as_bytes().last().unwrap_or(&b'0'), c)
            }
            _ => return Err(at_line(path, n, format!("unexpected `{w}`"))),
        };
        if let Some((_, li)) = head.ids.iter().find(|(c, _)| c == code) {
            if val == b'1' {
                cur |= 1 << li;
            } else {
                cur &= !(1 << li);
            }
        }
    }
    steps.push(((t as f64 * head.scale_ps) as u64, cur));
    Ok(steps)
}
