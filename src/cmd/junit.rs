//! `--junit FILE` of `build`, `golden` and `check`: JUnit XML (through
//! `quick-junit`) that CI servers read, one test case per step or preset,
//! a failure carrying its one-line result as message and the first
//! difference as text.

use std::path::Path;
use std::time::Duration;

use quick_junit::{NonSuccessKind, Report, TestCase, TestCaseStatus, TestSuite};

/// One test case.
pub struct Case {
    pub name: String,
    pub seconds: f64,
    pub outcome: Outcome,
}

pub enum Outcome {
    Passed,
    /// One line, then the detail (the first difference, a log tail).
    Failed(String, String),
    Skipped(String),
}

impl Case {
    pub fn of_step(s: &report::Step) -> Case {
        Case {
            name: s.id.clone(),
            seconds: s.seconds,
            outcome: match s.status {
                report::Status::Ok => Outcome::Passed,
                report::Status::Failed => Outcome::Failed(s.summary.clone(), s.detail.clone()),
                report::Status::Skipped => Outcome::Skipped(s.summary.clone()),
            },
        }
    }
}

/// Refuses, before any work, a `--junit` path whose folder does not exist
/// or that is a directory: the message printed, exit 2.
pub fn check_writable(path: Option<&Path>) -> Result<(), u8> {
    let Some(path) = path else {
        return Ok(());
    };
    super::output_file("--junit", path)
        .map(|_| ())
        .map_err(|e| {
            eprintln!("error: {e}");
            2
        })
}

/// The XML of one suite `suite` holding `cases`.
pub fn xml(suite: &str, cases: &[Case]) -> String {
    let mut ts = TestSuite::new(suite);
    for c in cases {
        let status = match &c.outcome {
            Outcome::Passed => TestCaseStatus::success(),
            Outcome::Failed(msg, detail) => {
                let mut st = TestCaseStatus::non_success(NonSuccessKind::Failure);
                st.set_message(msg.as_str());
                if !detail.is_empty() {
                    st.set_description(detail.as_str());
                }
                st
            }
            Outcome::Skipped(why) => {
                let mut st = TestCaseStatus::skipped();
                st.set_message(why.as_str());
                st
            }
        };
        let mut tc = TestCase::new(c.name.as_str(), status);
        tc.set_classname(suite);
        tc.set_time(Duration::from_secs_f64(c.seconds.max(0.0)));
        ts.add_test_case(tc);
    }
    let mut r = Report::new("slotforge");
    r.add_test_suite(ts);
    r.to_string()
        .expect("JUnit XML of plain strings serializes")
}

/// Writes the XML to `path` atomically.
pub fn write(path: &Path, suite: &str, cases: &[Case]) -> Result<(), String> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let name = path
        .file_name()
        .ok_or_else(|| format!("--junit {}: not a file name", path.display()))?
        .to_string_lossy();
    super::write_atomic(dir, &name, &xml(suite, cases))
}
