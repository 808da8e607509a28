//! The link's bytes as named, timed samples: `link::Decoder` (the packet
//! format's one home) with each record's sampling instant from the
//! schedule (`lut_gen::PacketInstants`; a mix with modes: its packet's
//! mode's schedule, and the frame before's for the records it carries over).

use link::{Decoded, Decoder, Stats};
use lut_gen::{PacketInstants, Schedule};

/// One sample of a good packet, with its sampling instant.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Sample {
    /// The packet's frame, unwrapped from the first packet decoded on.
    pub frame: u64,
    pub slice: u16,
    /// The mode of the packet's frame (an index into
    /// [`Samples::mode_names`]); 0 for a mix without modes.
    pub mode: u8,
    /// The channel's position in the mix file.
    pub channel: u16,
    pub value: u16,
    /// The sampling instant in cycles after cycle 0; `None` where the
    /// schedule has no instant left for the record.
    pub cycle: Option<u64>,
}

/// The streaming decoder of one mix's link.
#[derive(Debug, Clone)]
pub struct Samples {
    dec: Decoder,
    names: Vec<String>,
    times: PacketInstants,
    /// A mix with modes: each mode's name and packet instants.
    modes: Vec<(String, PacketInstants)>,
    clock_hz: u64,
    got: Vec<Decoded>,
}

impl Samples {
    /// The decoder of `s`'s link; `None` for a mix without a `[link]`.
    pub fn new(s: &Schedule) -> Option<Samples> {
        s.mix.link?;
        let names = s.mode_plan().map(|m| m.names.clone()).unwrap_or_default();
        let modes = match s.modes.len() > 1 {
            true => names
                .into_iter()
                .zip(s.modes.iter().map(PacketInstants::new))
                .collect(),
            false => Vec::new(),
        };
        // the header's mode bits: what the gateware's link sends (`LinkPlan::tx_config`)
        let mode_bits = s.mode_plan().map_or(0, |m| m.select_bits());
        Some(Samples {
            dec: Decoder::with_modes(s.grid.slices_per_frame, mode_bits),
            names: s.mix.channels.iter().map(|c| c.name.clone()).collect(),
            times: PacketInstants::new(s),
            modes,
            clock_hz: s.grid.clock_hz,
            got: Vec::new(),
        })
    }

    /// The channels' names, in the mix's order.
    pub fn channel_names(&self) -> &[String] {
        &self.names
    }

    /// The modes' names (empty for a mix without modes).
    pub fn mode_names(&self) -> Vec<&str> {
        self.modes.iter().map(|m| m.0.as_str()).collect()
    }

    /// A channel's name (`#N` for an index the mix does not have).
    pub fn name(&self, channel: u16) -> String {
        self.names
            .get(channel as usize)
            .cloned()
            .unwrap_or_else(|| format!("#{channel}"))
    }

    /// A sample's sampling instant in seconds after cycle 0 as text,
    /// rounded once to 1 ps (`lut_gen::seconds`, as `sim --samples` writes
    /// it); empty where it has none.
    pub fn seconds(&self, x: &Sample) -> String {
        x.cycle
            .map(|c| lut_gen::seconds(c, self.clock_hz))
            .unwrap_or_default()
    }

    /// Feed received bytes; `out` gets the samples of every packet they complete.
    pub fn push(&mut self, bytes: &[u8], out: &mut Vec<Sample>) {
        let mut got = std::mem::take(&mut self.got);
        got.clear();
        self.dec.push(bytes, &mut got);
        for packet in got.chunk_by(|a, b| (a.frame, a.slice) == (b.frame, b.slice)) {
            self.time(packet, out);
        }
        self.got = got;
    }

    /// One packet's samples (in order), timed.
    fn time(&self, packet: &[Decoded], out: &mut Vec<Sample>) {
        let chans: Vec<u16> = packet.iter().map(|x| x.channel).collect();
        let p = &packet[0];
        let times = match self.modes.get(p.mode as usize) {
            Some((_, own)) => {
                let prev = self.modes.get(p.prev_mode as usize).map_or(own, |m| &m.1);
                own.cycles_after(prev, p.frame, p.slice, &chans)
            }
            None => self.times.cycles(p.frame, p.slice, &chans),
        };
        out.extend(packet.iter().zip(times).map(|(x, cycle)| Sample {
            frame: x.frame,
            slice: x.slice,
            mode: x.mode,
            channel: x.channel,
            value: x.value,
            cycle,
        }));
    }

    /// The counts so far.
    pub fn stats(&self) -> &Stats {
        self.dec.stats()
    }

    /// The stream ended: the counts, a packet still open counted as in flight.
    pub fn finish(&mut self) -> Stats {
        self.dec.finish()
    }
}
