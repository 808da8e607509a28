use lut_gen::for_tests::plan_one;
use lut_gen::plan_link as memo_plan;
use lut_gen::Schedule;

fn eskin_uart() -> Schedule {
    let text = include_str!("../../../mixes/eskin34-uart.toml");
    let m = lut_gen::parse(std::path::Path::new("t.toml"), text).unwrap();
    lut_gen::synthesize(&m).unwrap()
}

/// An edited schedule is planned anew, never given the plan of the
/// schedule it was copied from; the unedited one gets its own back.
#[test]
fn an_edited_schedule_gets_its_own_plan() {
    let s = eskin_uart();
    let first = memo_plan(&s).unwrap().unwrap();
    let mut slow = s.clone();
    slow.mix.link.as_mut().unwrap().baud = 2_000_000;
    let edited = memo_plan(&slow).unwrap().unwrap();
    assert_ne!(edited.baud_divider, first.baud_divider);
    let spec = slow.mix.link.unwrap();
    assert_eq!(Ok(edited), plan_one(&slow, &spec));
    assert_eq!(memo_plan(&s).unwrap().unwrap(), first);
}
