//! The last few link plans, by schedule: a plan of a mix with modes runs
//! every switch between two modes through the transmitter's cycle model,
//! and the model, the checker, the engines and the campaign each ask for
//! the plan of the same schedule again for every run (a fault campaign on
//! a three-mode mix spent most of its time planning the same link).
//!
//! Keyed by the whole schedule (`PartialEq`), not a name or a hash of part
//! of it, so an edited schedule never gets a stale plan.

use std::sync::Mutex;

use super::{LinkInfeasible, LinkPlan};
use crate::schedule::Schedule;

type Plan = Result<LinkPlan, LinkInfeasible>;

/// Plans kept: a run holds one schedule and its modes' at most; a campaign
/// alternates its mix and a few random ones.
const KEPT: usize = 8;

static PLANS: Mutex<Vec<(Schedule, Plan)>> = Mutex::new(Vec::new());

/// `s`'s plan, from the memo or `make` (run without the lock held, so two
/// threads planning different mixes do not wait for each other).
pub(super) fn plan(s: &Schedule, make: impl FnOnce(&Schedule) -> Plan) -> Plan {
    if let Some(p) = lookup(s) {
        return p;
    }
    let p = make(s);
    let mut plans = PLANS.lock().unwrap_or_else(|e| e.into_inner());
    if !plans.iter().any(|(k, _)| k == s) {
        if plans.len() == KEPT {
            drop(plans.remove(0));
        }
        plans.push((s.clone(), p.clone()));
    }
    p
}

fn lookup(s: &Schedule) -> Option<Plan> {
    let plans = PLANS.lock().unwrap_or_else(|e| e.into_inner());
    plans.iter().find(|(k, _)| k == s).map(|(_, p)| p.clone())
}
