//! The one runner of the external checking tools (yosys, yosys-abc,
//! sigrok-cli): spawn with a time limit, tell "not installed" apart from "ran
//! and failed", keep the output for the report; and [`present`], the one
//! test of whether a tool is installed (the build's steps, `prove`'s
//! engines and the tests' tool policy, `testkit/src/tools.rs`, ask it).
//! It lives in the judge, the lowest crate that runs a tool (sigrok-cli for
//! `.sr` captures), so every crate above and every test binary can reach it.

use std::path::Path;
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
/// in `dir` (not pipes), so a chatty tool cannot block on a full pipe.
pub fn run(
    tool: &str,
    args: &[&str],
    dir: &Path,
    limit: Duration,
) -> Result<ToolOutput, ToolError> {
    let io = |e: std::io::Error| ToolError::Io(format!("{tool}: {e}"));
    let out_path = dir.join(format!("{tool}.stdout"));
    let err_path = dir.join(format!("{tool}.stderr"));
    let t0 = Instant::now();
    let mut child = match Command::new(tool)
        .args(args)
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(std::fs::File::create(&out_path).map_err(io)?)
        .stderr(std::fs::File::create(&err_path).map_err(io)?)
        .spawn()
    {
        Ok(c) => c,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(ToolError::Missing(tool.into()))
        }
        Err(e) => return Err(io(e)),
    };
    let status = loop {
        if let Some(st) = child.try_wait().map_err(io)? {
            break st;
        }
        if t0.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            return Err(ToolError::Timeout(tool.into(), limit.as_secs()));
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    Ok(ToolOutput {
        success: status.success(),
        stdout: std::fs::read_to_string(&out_path).unwrap_or_default(),
        stderr: std::fs::read_to_string(&err_path).unwrap_or_default(),
        seconds: t0.elapsed().as_secs_f64(),
    })
}
