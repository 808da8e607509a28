//! The `[[channel]]` tables, their mux inputs, and the checks across
//! channels (chained conversions, sync groups).

use std::collections::{BTreeMap, BTreeSet};
use std::ops::Range;

use toml::Spanned;

use super::bulk::Declared;
use super::check::Timing;
use super::raw::*;
use super::words::*;
use super::*;
use crate::parts::cycles_to_ns;

/// How far apart a sync group's sampling instants may be, in ns.
pub(crate) const SYNC_TOLERANCE_NS: u64 = 1_000;

/// (converter or mux input, chain member, front mux input).
pub(super) type InputKey = (u32, u32, Option<u32>);

/// The channels as read, before automatic inputs are assigned.
pub(super) struct ChannelDraft {
    pub(super) channels: Vec<Channel>,
    /// Per branch: (input, chain member, front mux input) -> the channel
    /// that has it, to name it in a clash.
    pub(super) used_inputs: Vec<BTreeMap<InputKey, String>>,
    /// Channels without an explicit input, in file order.
    pub(super) pending_auto: Vec<usize>,
    /// Sync tag -> (channel, where its `sync` is written).
    pub(super) sync_groups: BTreeMap<String, Vec<(usize, Range<usize>)>>,
}

impl Cx<'_> {
    /// Every `[[channel]]`; explicit inputs are taken here, automatic ones
    /// later so that they fill the gaps deterministically.
    pub(super) fn channels(
        &self,
        decl: &[Declared],
        branches: &[Branch],
        t: &Timing,
    ) -> Result<ChannelDraft, MixError> {
        let mut draft = ChannelDraft {
            channels: Vec::new(),
            used_inputs: vec![BTreeMap::new(); branches.len()],
            pending_auto: Vec::new(),
            sync_groups: BTreeMap::new(),
        };
        let mut channel_names = BTreeSet::new();
        for (i, d) in decl.iter().enumerate() {
            let c = &d.raw;
            let cname = c.name.get_ref().clone();
            if cname.trim().is_empty() {
                return Err(self.at(c.name.span(), d.field("name"), "must not be empty"));
            }
            if !channel_names.insert(cname.clone()) {
                return Err(self.at(
                    c.name.span(),
                    d.field("name"),
                    d.say(format!("duplicate channel name `{cname}`")),
                ));
            }
            let channel = self.channel(i, d, branches, t, &mut draft)?;
            draft.channels.push(channel);
        }
        Ok(draft)
    }

    /// One `[[channel]]` past its name.
    pub(super) fn channel(
        &self,
        i: usize,
        d: &Declared,
        branches: &[Branch],
        t: &Timing,
        draft: &mut ChannelDraft,
    ) -> Result<Channel, MixError> {
        let (c, name) = (&d.raw, d.raw.name.get_ref().clone());
        let f = |k: &str| d.field(k);
        let branch = self.channel_branch(d, branches)?;
        let rate_hz = self
            .positive(&c.rate_hz, &f("rate_hz"))
            .map_err(|e| MixError {
                message: d.say(e.message),
                ..e
            })?;
        let frame_us = t.frame_us;
        if !(rate_hz as u128 * frame_us as u128).is_multiple_of(1_000_000) {
            return Err(self.at(
                c.rate_hz.span(),
                f("rate_hz"),
                d.say(format!(
                    "{rate_hz} Hz gives {:.3} samples per {frame_us} us frame, not a whole number \
                     (rates must be multiples of {} Hz){}",
                    rate_hz as f64 * frame_us as f64 / 1e6,
                    hz_text(1e6 / frame_us as f64),
                    frames_that_fit(rate_hz, t.slice_us)
                )),
            ));
        }
        let member = self.channel_member(d, &branches[branch])?;
        let front_input = self.channel_front(d, &branches[branch])?;
        let input = match &c.input {
            None => {
                draft.pending_auto.push(i);
                u32::MAX
            }
            Some(v) => {
                let b = &branches[branch];
                let used = &mut draft.used_inputs[branch];
                self.channel_input(d, v, (member, front_input), b, used)?
            }
        };
        let bandwidth_hz = self.channel_bandwidth(d)?;
        let sync = match &c.sync {
            None => None,
            Some(s) => {
                if s.get_ref().trim().is_empty() {
                    return Err(self.at(s.span(), f("sync"), d.say("must not be empty")));
                }
                draft
                    .sync_groups
                    .entry(s.get_ref().clone())
                    .or_default()
                    .push((i, s.span()));
                Some(s.get_ref().clone())
            }
        };
        Ok(Channel {
            name,
            branch,
            rate_hz,
            input,
            front_input,
            kind: c.kind.clone(),
            bandwidth_hz,
            sync,
            member,
            rates: Vec::new(),
        })
    }

    /// `channel.branch`: a declared branch, by name.
    pub(super) fn channel_branch(
        &self,
        d: &Declared,
        branches: &[Branch],
    ) -> Result<usize, MixError> {
        let c = &d.raw;
        // Branch names are unique by now, so the first match is the one.
        branches
            .iter()
            .position(|b| b.name == *c.branch.get_ref())
            .ok_or_else(|| {
                self.at(
                    c.branch.span(),
                    d.field("branch"),
                    d.say(format!(
                        "unknown branch `{}` (declared: {})",
                        c.branch.get_ref(),
                        branches
                            .iter()
                            .map(|b| b.name.as_str())
                            .collect::<Vec<_>>()
                            .join(", ")
                    )),
                )
            })
    }

    /// `channel.member`: which part of the branch's chain, 0 unless given.
    pub(super) fn channel_member(&self, d: &Declared, b: &Branch) -> Result<u32, MixError> {
        let Some(m) = &d.raw.member else {
            return Ok(0);
        };
        let chain = b.chain;
        if *m.get_ref() < 0 || *m.get_ref() >= chain as i64 {
            return Err(self.at(
                m.span(),
                d.field("member"),
                d.say(format!(
                    "member {}{} is beyond branch `{}`: its chain of {chain} part(s) has members 0..={}",
                    m.get_ref(),
                    counted_from(*m.get_ref(), d.step),
                    b.name,
                    chain - 1
                )),
            ));
        }
        Ok(*m.get_ref() as u32)
    }

    /// `channel.front_input`: only on a branch with a front mux, within its
    /// devices, and with the converter `input` its output is wired to.
    pub(super) fn channel_front(&self, d: &Declared, b: &Branch) -> Result<Option<u32>, MixError> {
        let Some(v) = &d.raw.front_input else {
            return Ok(None);
        };
        let say = |m: String| self.at(v.span(), d.field("front_input"), d.say(m));
        if !b.fronted {
            return Err(say(format!(
                "branch `{}` has no front mux: front_input needs front_mux on the branch (with mux = \"internal\")",
                b.name
            )));
        }
        let capacity = b.mux.inputs * b.mux_devices;
        if *v.get_ref() < 0 || *v.get_ref() >= capacity as i64 {
            return Err(say(format!(
                "front input {}{} is beyond branch `{}`: {} front mux device(s) give front inputs 0..={}",
                v.get_ref(),
                counted_from(*v.get_ref(), d.step),
                b.name,
                b.mux_devices,
                capacity - 1
            )));
        }
        if d.raw.input.is_none() {
            return Err(say(
                "name the converter input the front mux's output is wired to with `input` as well"
                    .into(),
            ));
        }
        Ok(Some(*v.get_ref() as u32))
    }

    /// An explicit `channel.input`: on the branch's muxes and not taken by
    /// another channel of the same chain member (and front mux input).
    pub(super) fn channel_input(
        &self,
        d: &Declared,
        v: &Spanned<i64>,
        (member, front): (u32, Option<u32>),
        b: &Branch,
        used: &mut BTreeMap<InputKey, String>,
    ) -> Result<u32, MixError> {
        let capacity = b.input_capacity();
        if (b.mux.is_internal() || b.fronted)
            && (*v.get_ref() < 0 || *v.get_ref() >= capacity as i64)
        {
            return Err(self.at(
                v.span(),
                d.field("input"),
                d.say(format!(
                    "input {}{} is beyond branch `{}`: its converter `{}` has channels 0..={}",
                    v.get_ref(),
                    counted_from(*v.get_ref(), d.step),
                    b.name,
                    b.adc.name,
                    capacity - 1
                )),
            ));
        }
        if *v.get_ref() < 0 || *v.get_ref() >= capacity as i64 {
            return Err(self.at(
                v.span(),
                d.field("input"),
                d.say(format!(
                    "input {}{} is beyond branch `{}`: {} mux device(s) give inputs 0..={}",
                    v.get_ref(),
                    counted_from(*v.get_ref(), d.step),
                    b.name,
                    b.mux_devices,
                    capacity - 1
                )),
            ));
        }
        let inp = *v.get_ref() as u32;
        if let Some(other) = used.insert((inp, member, front), d.raw.name.get_ref().clone()) {
            let which = match front {
                Some(f) => format!(" with front_input {f}"),
                None if b.chain > 1 => format!(" (chain member {member})"),
                None => String::new(),
            };
            return Err(self.at(
                v.span(),
                d.field("input"),
                d.say(format!(
                    "input {inp}{which} of branch `{}` is already taken by channel `{other}`",
                    b.name
                )),
            ));
        }
        Ok(inp)
    }

    /// `channel.bandwidth_hz`: an integer or a float, positive and finite.
    pub(super) fn channel_bandwidth(&self, d: &Declared) -> Result<Option<f64>, MixError> {
        let Some(b) = &d.raw.bandwidth_hz else {
            return Ok(None);
        };
        let v = match b.get_ref() {
            toml::Value::Integer(i) => *i as f64,
            toml::Value::Float(x) => *x,
            other => {
                return Err(self.at(
                    b.span(),
                    d.field("bandwidth_hz"),
                    d.say(format!(
                        "got {}, expected a number of Hz",
                        value_words(other)
                    )),
                ))
            }
        };
        if !(v > 0.0 && v.is_finite()) {
            return Err(self.at(
                b.span(),
                d.field("bandwidth_hz"),
                d.say(format!("must be positive, got {v}")),
            ));
        }
        Ok(Some(v))
    }

    /// Channels without an input take the lowest free one of their chain
    /// member, in file order.
    pub(super) fn assign_auto_inputs(
        &self,
        decl: &[Declared],
        branches: &[Branch],
        draft: &mut ChannelDraft,
    ) -> Result<(), MixError> {
        let channels = &mut draft.channels;
        for &i in &draft.pending_auto {
            let b = channels[i].branch;
            let capacity = branches[b].input_capacity();
            let m = channels[i].member;
            let used_inputs = &mut draft.used_inputs;
            let taken = |k: u32| used_inputs[b].keys().any(|&(i, mm, _)| i == k && mm == m);
            let free = (0..capacity).find(|&k| !taken(k)).ok_or_else(|| {
                self.at(
                    decl[i].raw.name.span(),
                    decl[i].field("input"),
                    decl[i].say(format!(
                        "branch `{}` has no free mux input left ({} device(s), {} inputs); add mux_devices",
                        branches[b].name, branches[b].mux_devices, capacity
                    )),
                )
            })?;
            used_inputs[b].insert((free, m, None), channels[i].name.clone());
            channels[i].input = free;
        }
        Ok(())
    }

    /// On a fronted branch a converter input is wired either straight to
    /// a sensor or to the front mux's output, not both.
    pub(super) fn check_front_wiring(
        &self,
        decl: &[Declared],
        branches: &[Branch],
        channels: &[Channel],
    ) -> Result<(), MixError> {
        for (i, c) in channels.iter().enumerate() {
            self.check_front_device(decl, branches, channels, i)?;
            let Some(o) = channels[..i].iter().find(|o| {
                o.branch == c.branch
                    && o.input == c.input
                    && o.front_input.is_some() != c.front_input.is_some()
            }) else {
                continue;
            };
            let (fronted, straight) = if c.front_input.is_some() {
                (c, o)
            } else {
                (o, c)
            };
            let d = &decl[i];
            let span = d.raw.input.as_ref().map_or(d.raw.name.span(), |v| v.span());
            return Err(self.at(
                span,
                d.field("input"),
                d.say(format!(
                    "converter input {} of branch `{}` is wired through the front mux (`{}` has front_input {}) and straight (`{}` has none): a converter input is one or the other",
                    c.input,
                    branches[c.branch].name,
                    fronted.name,
                    fronted.front_input.unwrap_or(0),
                    straight.name
                )),
            ));
        }
        Ok(())
    }

    /// A front mux device has one output, wired to one converter input:
    /// the channels on its inputs name the same `input`.
    fn check_front_device(
        &self,
        decl: &[Declared],
        branches: &[Branch],
        channels: &[Channel],
        i: usize,
    ) -> Result<(), MixError> {
        let c = &channels[i];
        let Some(f) = c.front_input else {
            return Ok(());
        };
        let per = branches[c.branch].mux.inputs;
        let Some(o) = channels[..i].iter().find(|o| {
            o.branch == c.branch
                && o.input != c.input
                && o.front_input.is_some_and(|g| g / per == f / per)
        }) else {
            return Ok(());
        };
        let d = &decl[i];
        let span = d
            .raw
            .front_input
            .as_ref()
            .map_or(d.raw.name.span(), |v| v.span());
        let dev = f / per;
        Err(self.at(
            span,
            d.field("front_input"),
            d.say(format!(
                "front mux device {dev} of branch `{}` (front inputs {}..={}) has one output, wired to converter input {} by `{}`: front_input {f} would put it on input {} too",
                branches[c.branch].name,
                dev * per,
                dev * per + per - 1,
                o.input,
                o.name,
                c.input
            )),
        ))
    }

    /// Channels of one branch on one mux input are read in one conversion
    /// (one per chain member): they share every sampling instant.
    pub(super) fn check_chain_rates(
        &self,
        decl: &[Declared],
        branches: &[Branch],
        channels: &[Channel],
    ) -> Result<(), MixError> {
        for i in 0..channels.len() {
            for j in 0..i {
                let (a, c) = (&channels[j], &channels[i]);
                if a.same_conversion(c) && a.rate_hz != c.rate_hz {
                    return Err(self.at(
                        decl[i].raw.rate_hz.span(),
                        decl[i].field("rate_hz"),
                        decl[i].say(format!(
                            "`{}` ({} Hz) and `{}` ({} Hz) are chain members {} and {} of one conversion on branch `{}` (mux input {}): chained parts are sampled together, so they need one rate",
                            c.name, c.rate_hz, a.name, a.rate_hz, c.member, a.member,
                            branches[c.branch].name, c.input
                        )),
                    ));
                }
            }
        }
        Ok(())
    }

    /// A sync group has one rate and at most one conversion per branch.
    pub(super) fn check_sync_groups(
        &self,
        decl: &[Declared],
        branches: &[Branch],
        channels: &[Channel],
        sync_groups: &BTreeMap<String, Vec<(usize, Range<usize>)>>,
        (clock_hz, slice_cycles): (u64, u64),
    ) -> Result<(), MixError> {
        for (tag, members) in sync_groups {
            self.check_sync_instants(
                decl,
                branches,
                channels,
                (tag, members),
                (clock_hz, slice_cycles),
            )?;
            let mut seen = BTreeMap::new();
            let rate = channels[members[0].0].rate_hz;
            for (i, span) in members {
                let c = &channels[*i];
                if c.rate_hz != rate {
                    return Err(self.at(
                        span.clone(),
                        decl[*i].field("sync"),
                        decl[*i].say(format!(
                            "sync group `{tag}` mixes rates ({} Hz and {} Hz): synchronized channels share every sampling instant, so they need one rate",
                            rate, c.rate_hz
                        )),
                    ));
                }
                if let Some(other) = seen.insert(c.branch, *i) {
                    if channels[other].same_conversion(c) {
                        // Members of one chained conversion: one instant anyway.
                        continue;
                    }
                    return Err(self.at(
                        span.clone(),
                        decl[*i].field("sync"),
                        decl[*i].say(format!(
                            "sync group `{tag}` has `{}` and `{}` on the same branch `{}`: one ADC cannot sample both at one instant",
                            channels[other].name, c.name, branches[c.branch].name
                        )),
                    ));
                }
            }
        }
        Ok(())
    }

    /// A sync group's conversions start at one slot tick, and a part that
    /// holds its input earlier in its transaction than another member waits
    /// the difference (its hold-off, docs/timing.md "Hold-off"): refused
    /// when the wait and the transaction no longer fit a slice, or the
    /// branch's conversions per second at that length.
    pub(super) fn check_sync_instants(
        &self,
        decl: &[Declared],
        branches: &[Branch],
        channels: &[Channel],
        (tag, members): (&str, &[(usize, Range<usize>)]),
        (clock_hz, slice_cycles): (u64, u64),
    ) -> Result<(), MixError> {
        let timing = |c: usize| branches[channels[c].branch].timing(clock_hz).ok();
        let known: Vec<(usize, crate::parts::SpiTiming)> = members
            .iter()
            .filter_map(|(c, _)| timing(*c).map(|t| (*c, t)))
            .collect();
        let Some(&(late, lt)) = known
            .iter()
            .max_by_key(|(c, t)| (t.sample_cycles, usize::MAX - c))
        else {
            return Ok(());
        };
        for &(c, t) in &known {
            let hold = lt.sample_cycles - t.sample_cycles;
            if cycles_to_ns(hold, clock_hz) <= SYNC_TOLERANCE_NS as f64 {
                continue;
            }
            let held = hold + t.read_cycles + t.quiet_cycles;
            let b = channels[c].branch;
            let demand: u64 = channels
                .iter()
                .filter(|x| x.branch == b)
                .map(|x| x.rate_hz)
                .sum();
            let why = if held > slice_cycles {
                format!(
                    "its hold-off and transaction take {:.3} us, longer than a slice ({:.3} us)",
                    cycles_to_ns(held, clock_hz) / 1000.0,
                    cycles_to_ns(slice_cycles, clock_hz) / 1000.0
                )
            } else if demand as u128 * held as u128 > clock_hz as u128 {
                format!(
                    "its hold-off and transaction take {:.3} us, so the branch converts at most {:.0} times per second, and its channels ask {demand}",
                    cycles_to_ns(held, clock_hz) / 1000.0,
                    clock_hz as f64 / held as f64
                )
            } else {
                continue;
            };
            let span = &members.iter().find(|m| m.0 == c).expect("a member").1;
            let part = |c: usize| {
                let b = &branches[channels[c].branch];
                format!(
                    "`{}` on branch `{}` ({})",
                    channels[c].name, b.name, b.adc.name
                )
            };
            return Err(self.at(
                span.clone(),
                decl[c].field("sync"),
                decl[c].say(format!(
                    "sync group `{tag}` cannot hold at one instant: {} holds its input {:.3} us after its transaction starts ({}), so {} starts its transaction {:.3} us after the slot tick, and {why}",
                    part(late),
                    cycles_to_ns(lt.sample_cycles, clock_hz) / 1000.0,
                    branches[channels[late].branch].adc.sample.words(branches[channels[late].branch].adc.start),
                    part(c),
                    cycles_to_ns(hold, clock_hz) / 1000.0,
                )),
            ));
        }
        Ok(())
    }

    /// Members of one chained conversion are in one sync group or none.
    pub(super) fn check_chain_sync(
        &self,
        decl: &[Declared],
        channels: &[Channel],
    ) -> Result<(), MixError> {
        for i in 0..channels.len() {
            for j in 0..i {
                let (a, c) = (&channels[j], &channels[i]);
                if a.same_conversion(c) && a.sync != c.sync {
                    let d = &decl[i];
                    let span = d
                        .raw
                        .sync
                        .as_ref()
                        .map(|s| s.span())
                        .unwrap_or(d.raw.name.span());
                    return Err(self.at(
                        span,
                        d.field("sync"),
                        d.say(format!(
                            "`{}` and `{}` are read in one chained conversion, so they are in the same sync group or none: give them the same `sync`",
                            c.name, a.name
                        )),
                    ));
                }
            }
        }
        Ok(())
    }

    /// Every branch samples at least one channel.
    pub(super) fn check_branches_used(
        &self,
        raw: &RawMix,
        branches: &[Branch],
        channels: &[Channel],
    ) -> Result<(), MixError> {
        for (bi, b) in branches.iter().enumerate() {
            if !channels.iter().any(|c| c.branch == bi) {
                let span = raw.branch[bi].get_ref().name.span();
                return Err(self.at(
                    span,
                    format!("branch[{bi}].name"),
                    format!("branch `{}` has no channels", b.name),
                ));
            }
        }
        Ok(())
    }
}

/// For a channel of a bulk table: how its counted value came about
/// (`(40 + 7)`), since the user wrote only the first.
fn counted_from(value: i64, step: u32) -> String {
    if step == 0 {
        String::new()
    } else {
        format!(
            " ({} + {step}, counted up from the first channel's)",
            value - step as i64
        )
    }
}
