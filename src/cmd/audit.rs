//! `slotforge audit MIX [--json]`: does the mix fit, and how well?

use std::path::PathBuf;

use lut_gen::AuditReport;

#[derive(clap::Args)]
pub struct Args {
    /// The channel-mix file (TOML).
    pub mix: PathBuf,
    /// Print the report as JSON instead of the table.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub search: super::SearchLimit,
}

pub fn run(args: Args) -> u8 {
    let mix = match lut_gen::load(&args.mix) {
        Ok(m) => m,
        Err(e) => {
            eprintln!("error: {e}");
            return 2;
        }
    };
    let (report, diagnosis) = match lut_gen::synthesize_within(&mix, args.search.nodes) {
        Ok(s) => {
            // a line too slow for the mix: named on stderr as the parser
            // names a bad key (the report says it too, and exits 1)
            let mut report = AuditReport::of_schedule(&s);
            if let Some(Err(e)) = lut_gen::hostlink::plan(&s) {
                eprintln!("error: {}", e.at(&args.mix));
                // the report names the file as well as the line
                for x in report.errors.iter_mut().filter(|x| **x == e.message) {
                    *x = e.at(&args.mix);
                }
            }
            (report, None)
        }
        Err(why) => (AuditReport::of_infeasible(&mix, &why), Some(why)),
    };
    if args.json {
        print!("{}", report.to_json());
    } else if let Some(why) = &diagnosis {
        print!("{why}");
    } else {
        print!("{}", report.to_text());
    }
    match (report.feasible, report.verdict) {
        (true, _) => 0,
        (false, Some(v)) => super::verdict_exit(v),
        (false, None) => 1,
    }
}
