//! The one runner of the external tools (verilator, g++, iverilog, vvp,
//! yosys, yosys-abc, nextpnr-ice40, sigrok-cli, cvc5): spawn, in a working
//! directory and with a time limit when asked, tell "not installed" apart
//! from "ran and failed", keep the output for the report; and [`present`],
//! the one test of whether a tool is installed (the build's steps, `prove`'s
//! engines and the tests' tool policy, `testkit::tools`, ask it).  It lives
//! in the judge, the lowest crate that runs a tool (sigrok-cli for `.sr`
//! captures), so every crate above and every test binary can reach it.

use std::ffi::{OsStr, OsString};
use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// What a tool run gave.
#[derive(Debug, Clone)]
pub struct ToolOutput {
    pub success: bool,
    pub stdout: String,
    pub stderr: String,
    pub seconds: f64,
}

/// Why a tool gave no answer.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ToolError {
    /// The tool cannot be spawned (not installed or not on PATH).
    Missing(String),
    /// It ran past its time limit and was stopped.
    Timeout(String, u64),
    Io(String),
}

impl std::fmt::Display for ToolError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ToolError::Missing(t) => write!(f, "{t} is not installed (make tools)"),
            ToolError::Timeout(t, s) => write!(f, "{t} gave no answer within {s} s"),
            ToolError::Io(m) => f.write_str(m),
        }
    }
}

/// Whether `tool` can be spawned (installed and on PATH); its answer to
/// `--version` does not matter.
pub fn present(tool: &str) -> bool {
    Command::new(tool)
        .arg("--version")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok()
}

/// Runs `tool args` in `dir`, stopped after `limit`.  Output goes to files
/// in `dir` (`<tool>.stdout`, `<tool>.stderr`), kept beside the work.
pub fn run(
    tool: &str,
    args: &[&str],
    dir: &Path,
    limit: Duration,
) -> Result<ToolOutput, ToolError> {
    Tool::new(tool)
        .args(args)
        .current_dir(dir)
        .timeout(limit)
        .output_in(dir)
        .run()
}

/// One run of a tool: its arguments, where it runs, how long it may take
/// and where its output goes.  Output goes to files, never pipes, so a
/// chatty tool cannot block on a full pipe: anonymous temporary files
/// unless [`Tool::output_in`] names a folder to keep them in.
#[derive(Debug, Clone)]
pub struct Tool {
    program: String,
    args: Vec<OsString>,
    dir: Option<PathBuf>,
    limit: Option<Duration>,
    output_in: Option<PathBuf>,
}

impl Tool {
    pub fn new(program: &str) -> Tool {
        Tool {
            program: program.into(),
            args: Vec::new(),
            dir: None,
            limit: None,
            output_in: None,
        }
    }

    pub fn arg(mut self, a: impl AsRef<OsStr>) -> Tool {
        self.args.push(a.as_ref().to_owned());
        self
    }

    pub fn args<I: IntoIterator<Item = S>, S: AsRef<OsStr>>(mut self, args: I) -> Tool {
        self.args
            .extend(args.into_iter().map(|a| a.as_ref().to_owned()));
        self
    }

    /// Runs it in `dir` (default: this process's working directory).
    pub fn current_dir(mut self, dir: impl Into<PathBuf>) -> Tool {
        self.dir = Some(dir.into());
        self
    }

    /// Stops it after `limit` ([`ToolError::Timeout`]); default: no limit.
    pub fn timeout(mut self, limit: Duration) -> Tool {
        self.limit = Some(limit);
        self
    }

    /// Keeps its output as `<dir>/<program>.stdout` and `.stderr`.
    pub fn output_in(mut self, dir: impl Into<PathBuf>) -> Tool {
        self.output_in = Some(dir.into());
        self
    }

    /// Runs it to the end (or its time limit): a missing program is
    /// [`ToolError::Missing`]; a failing one is `success: false`.
    pub fn run(&self) -> Result<ToolOutput, ToolError> {
        let tool = self.program.as_str();
        let io = |e: std::io::Error| ToolError::Io(format!("{tool}: {e}"));
        let (mut out, mut err) = match &self.output_in {
            Some(d) => (
                kept(&d.join(format!("{tool}.stdout"))).map_err(io)?,
                kept(&d.join(format!("{tool}.stderr"))).map_err(io)?,
            ),
            None => (
                tempfile::tempfile().map_err(io)?,
                tempfile::tempfile().map_err(io)?,
            ),
        };
        let mut cmd = Command::new(tool);
        cmd.args(&self.args)
            .stdin(Stdio::null())
            .stdout(out.try_clone().map_err(io)?)
            .stderr(err.try_clone().map_err(io)?);
        if let Some(d) = &self.dir {
            cmd.current_dir(d);
        }
        let t0 = Instant::now();
        let mut child = match cmd.spawn() {
            Ok(c) => c,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                return Err(ToolError::Missing(tool.into()))
            }
            Err(e) => return Err(io(e)),
        };
        let status = match self.limit {
            None => child.wait().map_err(io)?,
            Some(limit) => loop {
                if let Some(st) = child.try_wait().map_err(io)? {
                    break st;
                }
                if t0.elapsed() > limit {
                    let _ = child.kill();
                    let _ = child.wait();
                    return Err(ToolError::Timeout(tool.into(), limit.as_secs()));
                }
                std::thread::sleep(Duration::from_millis(5));
            },
        };
        Ok(ToolOutput {
            success: status.success(),
            stdout: read_back(&mut out),
            stderr: read_back(&mut err),
            seconds: t0.elapsed().as_secs_f64(),
        })
    }
}

/// A file for a tool's output that is kept, opened to be read back too.
fn kept(path: &Path) -> std::io::Result<File> {
    std::fs::OpenOptions::new()
        .read(true)
        .write(true)
        .create(true)
        .truncate(true)
        .open(path)
}

/// What a tool wrote to `f`, from the start (not UTF-8: replaced, not lost).
fn read_back(f: &mut File) -> String {
    let mut bytes = Vec::new();
    let _ = f
        .seek(SeekFrom::Start(0))
        .and_then(|_| f.read_to_end(&mut bytes));
    String::from_utf8_lossy(&bytes).into_owned()
}
