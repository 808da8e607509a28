//! The speed chart of a build whose engines miss faults: the checker is
//! switched off (the judge's test switch), so the sample's engines catch
//! nothing; their misses are on the chart and in the methods table as
//! data, from the same figures (one test in this binary: the switch is
//! read once per process).

use campaign::{Engine, Plan, Target};

#[test]
fn an_engine_that_misses_is_charted_at_its_catch() {
    std::env::set_var(judge::switch::ENV, "model,invariants");
    let mix = lut_gen::load(&testkit::mix("tiny")).unwrap();
    let s = lut_gen::synthesize(&mix).unwrap();
    let mut plan = Plan::new(Target::Model, 3, 0);
    plan.sigrok = false;
    let c = campaign::campaign_with(&s, &plan).unwrap();
    assert!(!c.ok(), "the switch is on");
    let methods = campaign::methods(&s, &[(Engine::Rusthdl, 2)], 2);
    let m = &methods[0];
    assert!(m.faults_run > 0 && m.caught == 0, "{m:?}");
    assert_eq!(m.missed.len() as u64, m.faults_run);
    let (sec, line) = measure::speed(&c, &methods, &[], false);
    assert!(
        line.contains(&format!(
            "engine: rusthdl {:.4} s per run, 0 of {}",
            m.seconds_per_run(),
            m.faults_run
        )),
        "{line}"
    );
    // the methods table names each miss
    let (title, table) = &sec.tables[0];
    assert!(title.contains("sample"));
    let csv = table.csv();
    for f in &m.missed {
        assert!(csv.contains(f.as_str()), "{f}: {csv}");
    }
    // the chart's row and label are the table's figures
    let fig = &sec.figures[0];
    let row = fig
        .table
        .csv()
        .lines()
        .find(|l| l.starts_with("engine: rusthdl,"))
        .unwrap()
        .to_string();
    let cols: Vec<&str> = row.split(',').collect();
    assert_eq!(cols[1], m.faults_run.to_string());
    assert_eq!((cols[4], cols[5]), ("0", m.faults_run.to_string().as_str()));
    assert!(fig
        .svg
        .contains(&format!("engine: rusthdl (0 of {})", m.faults_run)));
}
