//! The exact search for offsets, used when first-fit leaves a unit unplaced.
//!
//! Two units sharing a branch collide exactly when their offsets are equal
//! modulo the gcd of their periods, so the problem splits into *components*:
//! branches joined by sync groups.  Components are searched one at a time, so
//! a dead end in one never makes the search revisit the others (searching
//! them jointly multiplied their trees: the mix in `properties.rs` that this
//! module was rewritten for).
//!
//! Each component is a depth-first search with forward checking: every
//! unplaced unit keeps, per offset, how many placed units block it, and a
//! placement that leaves some unit without a free offset is undone at once.
//! Pruning drops only subtrees with no solution, and the symmetry breaking
//! (the component's first unit at offset 0, interchangeable units in
//! increasing candidate rank) keeps at least one solution of every solvable
//! component, so an exhausted search is a proof that the grid has no
//! schedule.
//!
//! The first pass places units in their fixed order and tries offsets in
//! candidate order: it finds the lexicographically first schedule, the one
//! the earlier unpruned search found, so tables do not change with pruning.
//! Should that pass run out of its share of the bound, a fail-first pass
//! (the unit with the fewest free offsets next) decides the component.

use super::{candidate_offsets, Unit};

/// Placements the first (lexicographic) pass may try per component before
/// the fail-first pass takes over.
const LEXICOGRAPHIC_SHARE: u64 = 20_000;

/// What the search of one slot grid found.
pub(super) enum Outcome {
    /// Offsets of every unit (in `units` order) and the placements tried.
    Placed(Vec<u64>, u64),
    /// A component has no placement: every candidate was tried or pruned
    /// by a rule that keeps all solutions. The grid has no schedule.
    Exhausted,
    /// The bound ran out before a verdict: neither a schedule nor a proof.
    Bounded,
}

/// Searches every component of `units` (periods in slots of a grid of `sps`
/// slots per slice), within `budget` placements in all.
pub(super) fn search(units: &[Unit], branches: usize, sps: u64, budget: u64) -> Outcome {
    let mut offsets = vec![0; units.len()];
    let mut nodes = 0;
    let mut bounded = false;
    let parts = components(units, branches);
    // A component spanning branches has no schedule if one of its branches
    // alone (its units, each constraining only that branch) has none: such
    // proofs are small and cheap, whereas the joint search would rediscover
    // the dead branch under every placement of the others.
    for members in parts.iter().filter(|m| spans_branches(units, m)) {
        for b in branches_of(units, members) {
            let on_b: Vec<usize> = members
                .iter()
                .copied()
                .filter(|&u| units[u].branches.contains(&b))
                .collect();
            let share = LEXICOGRAPHIC_SHARE.min(budget.saturating_sub(nodes));
            let mut c = Component::new(units, &on_b, Some(b), sps, Order::FailFirst, share);
            let verdict = c.solve();
            nodes += c.nodes;
            if verdict == Some(false) {
                return Outcome::Exhausted;
            }
        }
    }
    for members in parts {
        let mut found = None;
        for order in [Order::Lexicographic, Order::FailFirst] {
            let share = match order {
                Order::Lexicographic => LEXICOGRAPHIC_SHARE.min(budget.saturating_sub(nodes)),
                Order::FailFirst => budget.saturating_sub(nodes),
            };
            let mut c = Component::new(units, &members, None, sps, order, share);
            let verdict = c.solve();
            nodes += c.nodes;
            match verdict {
                Some(true) => {
                    found = Some(c.offsets);
                    break;
                }
                // Exhausted: the other order cannot do better.
                Some(false) => return Outcome::Exhausted,
                None => {}
            }
        }
        match found {
            Some(local) => {
                for (&u, o) in members.iter().zip(local) {
                    offsets[u] = o.expect("a solved component places every unit");
                }
            }
            // Go on: a later component may still prove the grid infeasible.
            None => bounded = true,
        }
    }
    if bounded {
        Outcome::Bounded
    } else {
        Outcome::Placed(offsets, nodes)
    }
}

/// Units (indices into `units`, ascending) grouped by the branches they
/// share, directly or through sync groups; components ordered by first unit.
fn components(units: &[Unit], branches: usize) -> Vec<Vec<usize>> {
    let mut root: Vec<usize> = (0..branches).collect();
    fn find(root: &mut [usize], b: usize) -> usize {
        let mut r = b;
        while root[r] != r {
            r = root[r];
        }
        root[b] = r;
        r
    }
    for u in units {
        let first = find(&mut root, u.branches[0]);
        for &b in &u.branches[1..] {
            let r = find(&mut root, b);
            root[r] = first;
        }
    }
    let mut by_root: Vec<(usize, Vec<usize>)> = Vec::new();
    for (i, u) in units.iter().enumerate() {
        let r = find(&mut root, u.branches[0]);
        match by_root.iter_mut().find(|(k, _)| *k == r) {
            Some((_, m)) => m.push(i),
            None => by_root.push((r, vec![i])),
        }
    }
    by_root.into_iter().map(|(_, m)| m).collect()
}

fn spans_branches(units: &[Unit], members: &[usize]) -> bool {
    branches_of(units, members).len() > 1
}

fn branches_of(units: &[Unit], members: &[usize]) -> Vec<usize> {
    let mut b: Vec<usize> = members
        .iter()
        .flat_map(|&u| units[u].branches.iter().copied())
        .collect();
    b.sort_unstable();
    b.dedup();
    b
}

#[derive(Clone, Copy, PartialEq)]
enum Order {
    Lexicographic,
    FailFirst,
}

/// The search state of one component; units are indexed locally.
struct Component {
    period: Vec<u64>,
    /// Units sharing a branch with each unit, with the gcd of the periods.
    neighbours: Vec<Vec<(usize, u64)>>,
    /// Offsets in candidate order (rank = position).
    candidates: Vec<Vec<u64>>,
    /// The previous unit of the same period on the same branches: swapping
    /// two such units' offsets maps schedules to schedules.
    twin_before: Vec<Option<usize>>,
    /// Per unit and offset: how many placed units block it.
    blocked: Vec<Vec<u32>>,
    /// Per unit: offsets no placed unit blocks.
    free: Vec<u64>,
    offsets: Vec<Option<u64>>,
    ranks: Vec<usize>,
    placed: usize,
    order: Order,
    nodes: u64,
    budget: u64,
}

impl Component {
    /// `only`: a relaxation where units constrain one another on this branch only.
    fn new(
        units: &[Unit],
        members: &[usize],
        only: Option<usize>,
        sps: u64,
        order: Order,
        budget: u64,
    ) -> Self {
        let us: Vec<&Unit> = members.iter().map(|&m| &units[m]).collect();
        let n = us.len();
        let shares = |a: &Unit, b: &Unit| {
            a.branches
                .iter()
                .any(|x| b.branches.contains(x) && only.is_none_or(|o| o == *x))
        };
        let neighbours = (0..n)
            .map(|i| {
                (0..n)
                    .filter(|&j| j != i && shares(us[i], us[j]))
                    .map(|j| (j, gcd(us[i].period, us[j].period)))
                    .collect()
            })
            .collect();
        let twin_before = (0..n)
            .map(|i| {
                (0..i)
                    .rev()
                    .find(|&j| us[j].period == us[i].period && us[j].branches == us[i].branches)
            })
            .collect();
        Component {
            period: us.iter().map(|u| u.period).collect(),
            neighbours,
            candidates: us
                .iter()
                .map(|u| candidate_offsets(u.period, sps).collect())
                .collect(),
            twin_before,
            blocked: us.iter().map(|u| vec![0; u.period as usize]).collect(),
            free: us.iter().map(|u| u.period).collect(),
            offsets: vec![None; n],
            ranks: vec![0; n],
            placed: 0,
            order,
            nodes: 0,
            budget,
        }
    }

    /// `Some(true)`: placed; `Some(false)`: proved impossible; `None`: bound hit.
    fn solve(&mut self) -> Option<bool> {
        let found = self.descend();
        if found {
            Some(true)
        } else if self.nodes > self.budget {
            None
        } else {
            Some(false)
        }
    }

    /// The unit to place next, if any is left.
    fn next_unit(&self) -> Option<usize> {
        // A unit waits for its twin, so twins are placed in index order
        // (what the increasing-rank rule assumes).
        let ready = (0..self.offsets.len()).filter(|&i| {
            self.offsets[i].is_none()
                && self.twin_before[i].is_none_or(|t| self.offsets[t].is_some())
        });
        match self.order {
            Order::Lexicographic => ready.min(),
            Order::FailFirst => ready.min_by_key(|&i| {
                (
                    self.free[i] * 64 / self.period[i],
                    std::cmp::Reverse(self.neighbours[i].len()),
                )
            }),
        }
    }

    fn descend(&mut self) -> bool {
        let Some(i) = self.next_unit() else {
            return true;
        };
        let min_rank = self.twin_before[i].map_or(0, |t| self.ranks[t] + 1);
        // Translation maps schedules to schedules: the first unit may sit at 0.
        let max_rank = if self.placed == 0 { 1 } else { usize::MAX };
        for rank in min_rank..self.candidates[i].len().min(max_rank) {
            let o = self.candidates[i][rank];
            if self.blocked[i][o as usize] > 0 {
                continue;
            }
            self.nodes += 1;
            if self.nodes > self.budget {
                return false;
            }
            let alive = self.place(i, o, rank);
            if alive && self.descend() {
                return true;
            }
            self.unplace(i, o);
            if self.nodes > self.budget {
                return false;
            }
        }
        false
    }

    /// Places unit `i` at `o`; false if some unplaced unit is left with no free offset.
    fn place(&mut self, i: usize, o: u64, rank: usize) -> bool {
        self.ranks[i] = rank;
        self.placed += 1;
        let alive = self.block(i, o, true);
        self.offsets[i] = Some(o);
        alive
    }

    /// Undoes `place(i, o, _)`; the unplaced units are the same as then.
    fn unplace(&mut self, i: usize, o: u64) {
        self.offsets[i] = None;
        self.placed -= 1;
        self.block(i, o, false);
    }

    /// Counts (`on`) or uncounts unit `i` at `o` against every unplaced
    /// neighbour's offsets that would meet it; false if one is left with none.
    fn block(&mut self, i: usize, o: u64, on: bool) -> bool {
        let mut alive = true;
        for k in 0..self.neighbours[i].len() {
            let (j, g) = self.neighbours[i][k];
            if self.offsets[j].is_some() {
                continue;
            }
            for x in (o % g..self.period[j]).step_by(g as usize) {
                let b = &mut self.blocked[j][x as usize];
                let was_free = *b == 0;
                *b = if on { *b + 1 } else { *b - 1 };
                match (was_free, *b == 0) {
                    (true, false) => self.free[j] -= 1,
                    (false, true) => self.free[j] += 1,
                    _ => {}
                }
            }
            alive &= self.free[j] > 0;
        }
        alive
    }
}

fn gcd(mut a: u64, mut b: u64) -> u64 {
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a
}
