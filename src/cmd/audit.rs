//! `slotforge audit MIX [--json] [--fixes DIR]`: does the mix fit, how
//! well, and if not, which changes (each tried first) make it fit?

use std::path::{Path, PathBuf};

use lut_gen::AuditReport;
use lut_gen::FixSearch;

#[derive(clap::Args)]
pub struct Args {
    /// The channel-mix file (TOML).
    pub mix: PathBuf,
    /// Print the report as JSON instead of the table.
    #[arg(long)]
    pub json: bool,
    /// For a mix that does not fit: write each fix offered as a complete
    /// mix file DIR/fix-<n>.toml (n from 1, in the printed order), each one
    /// audited feasible. DIR is created if missing; one that holds fix
    /// files already is refused, nothing written.
    #[arg(long, value_name = "DIR")]
    pub fixes: Option<PathBuf>,
    #[command(flatten)]
    pub search: super::SearchLimit,
}

pub fn run(args: Args) -> u8 {
    if let Some(dir) = &args.fixes {
        if let Err(e) = fresh_fix_dir(dir) {
            eprintln!("error: {e}");
            return 2;
        }
    }
    let mix = match lut_gen::load(&args.mix) {
        Ok(m) => m,
        Err(e) => {
            eprintln!("error: {e}");
            unloadable(&args);
            return 2;
        }
    };
    let (report, diagnosis) = match lut_gen::synthesize_within(&mix, args.search.nodes) {
        Ok(s) => {
            // a line too slow for the mix: named on stderr as the parser
            // names a bad key (the report says it too, and exits 1)
            let mut report = AuditReport::of_schedule(&s);
            let mut found = None;
            if let Some(Err(e)) = lut_gen::plan_link(&s) {
                eprintln!("error: {}", e.at(&args.mix));
                // the report names the file as well as the line
                for x in report.errors.iter_mut().filter(|x| **x == e.message) {
                    *x = e.at(&args.mix);
                }
                // a faster line, tried on the mix before it is offered
                let mut f = match std::fs::read_to_string(&args.mix) {
                    Ok(text) => lut_gen::search_fixes_link(
                        &args.mix,
                        &text,
                        &s,
                        e.min_baud.unwrap_or(f64::NAN),
                    ),
                    Err(_) => FixSearch {
                        fixes: Vec::new(),
                        tried: 0,
                    },
                };
                if let Err(code) = write_all(&args, &mut f) {
                    return code;
                }
                report.fixes_tried = Some(f.tried);
                report.fixes = Some(f.fixes.clone());
                found = Some(f);
            } else if let Some(dir) = &args.fixes {
                eprintln!("the mix fits: no fixes written to {}", dir.display());
            }
            (report, found.map(Diagnosis::Link))
        }
        Err(mut why) => {
            // advice from counts alone is not printed: the fixes replace
            // it, each one tried on the mix first
            why.suggestions.clear();
            let mut found = search(&args.mix, &mix, &why);
            if let Err(code) = write_all(&args, &mut found) {
                return code;
            }
            let mut report = AuditReport::of_infeasible(&mix, &why);
            report.fixes_tried = Some(found.tried);
            report.fixes = Some(found.fixes.clone());
            (report, Some(Diagnosis::Schedule(why, found)))
        }
    };
    if args.json {
        print!("{}", report.to_json());
    } else {
        match &diagnosis {
            Some(Diagnosis::Schedule(why, found)) => print!("{why}{found}"),
            Some(Diagnosis::Link(found)) if found.fixes.is_empty() => println!(
                "{}  no fix found: no standard baud that this clock divides within {} % carries the mix ({} tried)",
                report.to_text(),
                lut_gen::MAX_BAUD_ERROR_PCT,
                found.tried
            ),
            Some(Diagnosis::Link(found)) => print!("{}{found}", report.to_text()),
            None => print!("{}", report.to_text()),
        }
    }
    match (report.feasible, report.verdict) {
        (true, _) => 0,
        (false, Some(v)) => super::verdict_exit(v),
        (false, None) => 1,
    }
}

/// Why a mix does not fit, with the fixes tried for it.
enum Diagnosis {
    /// No schedule.
    Schedule(lut_gen::Infeasible, FixSearch),
    /// A schedule, and a UART too slow for it.
    Link(FixSearch),
}

/// The fixes of a loaded mix without a schedule (the file's own text is
/// edited, so it is read again).
fn search(path: &Path, mix: &lut_gen::Mix, why: &lut_gen::Infeasible) -> FixSearch {
    match std::fs::read_to_string(path) {
        Ok(text) => lut_gen::search_fixes(path, &text, mix, why),
        Err(_) => FixSearch {
            fixes: Vec::new(),
            tried: 0,
        },
    }
}

/// A mix the loader refused: if more mux devices make it load and fit,
/// say which (after the error), and write them when asked.
fn unloadable(args: &Args) {
    let Ok(text) = std::fs::read_to_string(&args.mix) else {
        return;
    };
    let mut found = lut_gen::search_fixes_unloadable(&args.mix, &text);
    if found.fixes.is_empty() {
        return;
    }
    if write_all(args, &mut found).is_err() {
        return;
    }
    eprint!("{found}");
}

/// `--fixes DIR`: refused before any work if DIR holds fix files already.
fn fresh_fix_dir(dir: &Path) -> Result<(), String> {
    if !dir.exists() {
        return Ok(());
    }
    if !dir.is_dir() {
        return Err(format!("{}: exists and is not a folder", dir.display()));
    }
    let entries = std::fs::read_dir(dir)
        .map_err(|e| format!("{}: cannot read: {}", dir.display(), lut_gen::io_words(&e)))?;
    let mut taken: Vec<String> = entries
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with("fix-") && n.ends_with(".toml"))
        .collect();
    taken.sort();
    if taken.is_empty() {
        return Ok(());
    }
    Err(format!(
        "{}: holds fix files already ({}): nothing written; give --fixes a new or empty folder",
        dir.display(),
        taken.join(", ")
    ))
}

/// Writes every fix as `DIR/fix-<n>.toml` and records where.
fn write_all(args: &Args, found: &mut FixSearch) -> Result<(), u8> {
    let Some(dir) = &args.fixes else {
        return Ok(());
    };
    if found.fixes.is_empty() {
        eprintln!("no fix found: nothing written to {}", dir.display());
        return Ok(());
    }
    let names: Vec<String> = (1..=found.fixes.len())
        .map(|n| format!("fix-{n}.toml"))
        .collect();
    let files: Vec<(&str, String)> = names
        .iter()
        .zip(&found.fixes)
        .map(|(n, f)| (n.as_str(), f.text.clone()))
        .collect();
    super::write_files(dir, &files)?;
    for (n, f) in names.iter().zip(&mut found.fixes) {
        f.file = Some(dir.join(n).display().to_string());
    }
    eprintln!(
        "wrote {} fix file(s) to {}: {}",
        names.len(),
        dir.display(),
        names.join(", ")
    );
    Ok(())
}
