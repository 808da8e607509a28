//! Why a simulation could not run (exit 2), as opposed to a failed check.

use std::fmt;

/// Why the Verilator back end could not run (a bad environment: exit 2).
#[derive(Debug)]
pub enum BackendError {
    /// A tool is not installed.
    MissingTool {
        tool: String,
        hint: String,
    },
    /// A build step failed; `log` has its output.
    Build {
        step: String,
        log: String,
    },
    Io(String),
    Other(String),
}

impl fmt::Display for BackendError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            BackendError::MissingTool { tool, hint } => {
                write!(f, "`{tool}` is not installed or not on PATH ({hint})")
            }
            BackendError::Build { step, log } => write!(f, "{step} failed:\n{log}"),
            BackendError::Io(m) | BackendError::Other(m) => f.write_str(m),
        }
    }
}

impl std::error::Error for BackendError {}

/// Why a simulation could not run (exit 2), as opposed to a failed check.
#[derive(Debug)]
pub enum SimError {
    /// The gateware cannot be generated for this schedule.
    Hdl(String),
    Backend(BackendError),
    Io(String),
    /// Outside Verilog (`--rtl`) that cannot be simulated: unreadable, no
    /// `slotforge_top`, a port off the contract, or a back end that runs no Verilog.
    Rtl(crate::rtl::RtlError),
}

impl fmt::Display for SimError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SimError::Hdl(m) => write!(f, "gateware: {m}"),
            SimError::Backend(e) => write!(f, "simulation back end: {e}"),
            SimError::Io(m) => f.write_str(m),
            SimError::Rtl(e) => write!(f, "--rtl: {e}"),
        }
    }
}

impl std::error::Error for SimError {}

impl From<BackendError> for SimError {
    fn from(e: BackendError) -> Self {
        SimError::Backend(e)
    }
}
