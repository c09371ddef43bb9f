//! Simulated links of the virtual-time engine: each direction of each link has its own
//! latency, jitter, loss, duplication, reordering and cuts, and draws its random choices from
//! its own seeded stream, so a link's fate sequence depends only on the seed and on what was
//! sent over it.
//!
//! ```
//! use mmic_host::sim::engine::link::{Fate, Link, LinkModel};
//! let model = LinkModel { latency_us: 2_000, ..LinkModel::default() };
//! let mut l = Link::new(model, 0.0, 7, true);
//! let sent = l.send(10_000);
//! assert_eq!(sent.fate, Fate::Delivered);
//! assert_eq!(sent.at_us, [12_000]);
//! ```

/// How one direction of a link treats packets (the loss comes from the run's per-link loss
/// options, `--wifi-loss` and the like, so that both engines take them the same way).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LinkModel {
    /// Fixed delay from write to arrival, µs.
    pub latency_us: u64,
    /// Extra delay, uniform in 0..=jitter_us, per packet, µs. On a stream (a serial line, a
    /// TCP connection) packets still arrive in order: a packet waits for the one before it.
    pub jitter_us: u64,
    /// Probability that a packet arrives twice (the copy after the original, with its own
    /// delay).
    pub duplicate: f64,
    /// Probability that a packet is held back by [`LinkModel::reorder_us`] more, so that later
    /// packets overtake it (also on a stream: a reordering link is a fault model).
    pub reorder: f64,
    /// How much longer a reordered packet takes, µs.
    pub reorder_us: u64,
    /// Intervals `[from, to)` of simulated ms in which the link carries nothing (`to` none:
    /// from then on).
    pub cuts: Vec<(u32, Option<u32>)>,
}

impl LinkModel {
    /// A serial line: 1 ms per packet (a 66-byte heartbeat takes 5.7 ms at 115,200 baud; the
    /// packets here are shorter or the line faster), in order, nothing else.
    pub fn serial() -> LinkModel {
        LinkModel {
            latency_us: 1_000,
            ..LinkModel::default()
        }
    }

    /// The WiFi link on a quiet network: 2 ms, up to 1 ms of jitter.
    pub fn wifi() -> LinkModel {
        LinkModel {
            latency_us: 2_000,
            jitter_us: 1_000,
            ..LinkModel::default()
        }
    }

    /// Whether the link is cut at `now_ms`.
    pub fn cut_at(&self, now_ms: u32) -> bool {
        self.cuts
            .iter()
            .any(|&(from, to)| now_ms >= from && to.is_none_or(|t| now_ms < t))
    }
}

/// What became of a packet written to a link.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fate {
    /// It arrives (once, or twice when duplicated).
    Delivered,
    /// Lost (injected loss).
    Lost,
    /// The link is cut.
    Cut,
}

impl Fate {
    /// The fate's name in the log.
    pub const fn name(self) -> &'static str {
        match self {
            Fate::Delivered => "delivered",
            Fate::Lost => "lost",
            Fate::Cut => "cut",
        }
    }
}

/// A packet's journey: its fate and when each copy arrives (none when lost or cut; two when
/// duplicated, the original first).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Sent {
    /// What became of it.
    pub fate: Fate,
    /// Arrival times of its copies, µs (inline: a packet sent is no allocation).
    pub at_us: heapless::Vec<u64, 2>,
}

/// One direction of a link.
#[derive(Debug, Clone)]
pub struct Link {
    model: LinkModel,
    loss: f64,
    rng: fastrand::Rng,
    /// A stream keeps order: no packet arrives before the one written before it.
    stream: bool,
    last_at: u64,
}

impl Link {
    /// A link with `model`, losing each packet with probability `loss`, drawing from the stream
    /// of `seed`; a `stream` keeps order (serial lines, TCP) unless the model reorders.
    pub fn new(model: LinkModel, loss: f64, seed: u64, stream: bool) -> Link {
        Link {
            model,
            loss,
            rng: fastrand::Rng::with_seed(seed),
            stream,
            last_at: 0,
        }
    }

    /// The link's model.
    pub fn model(&self) -> &LinkModel {
        &self.model
    }

    /// A packet written at `now_us`: its fate and arrival times. Every random choice is drawn
    /// whatever the outcome, so that one packet's fate never shifts the next one's draws.
    pub fn send(&mut self, now_us: u64) -> Sent {
        let (lost, dup, reorder) = (self.rng.f64(), self.rng.f64(), self.rng.f64());
        let (j1, j2) = (self.jitter(), self.jitter());
        if self.model.cut_at((now_us / 1000) as u32) {
            return Sent {
                fate: Fate::Cut,
                at_us: heapless::Vec::new(),
            };
        }
        if lost < self.loss {
            return Sent {
                fate: Fate::Lost,
                at_us: heapless::Vec::new(),
            };
        }
        let held = reorder < self.model.reorder;
        let mut first = now_us + self.model.latency_us + j1;
        if held {
            first += self.model.reorder_us;
        } else if self.stream {
            first = first.max(self.last_at);
        }
        let mut at_us = heapless::Vec::new();
        // Two copies at most: the vector holds them, so neither push can fail.
        let _ = at_us.push(first);
        if dup < self.model.duplicate {
            let _ = at_us.push(first.max(now_us + self.model.latency_us + j2));
        }
        if !held {
            self.last_at = self.last_at.max(*at_us.iter().max().unwrap_or(&first));
        }
        Sent {
            fate: Fate::Delivered,
            at_us,
        }
    }

    fn jitter(&mut self) -> u64 {
        if self.model.jitter_us == 0 {
            0
        } else {
            self.rng.u64(0..=self.model.jitter_us)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_stream_keeps_order_under_jitter_and_a_datagram_link_does_not() {
        let model = LinkModel {
            latency_us: 1_000,
            jitter_us: 5_000,
            ..LinkModel::default()
        };
        let times = |stream: bool| -> Vec<u64> {
            let mut l = Link::new(model.clone(), 0.0, 3, stream);
            (0..200).map(|i| l.send(i * 100).at_us[0]).collect()
        };
        let s = times(true);
        assert!(
            s.windows(2).all(|w| w[0] <= w[1]),
            "a stream arrives in order"
        );
        let d = times(false);
        assert!(
            d.windows(2).any(|w| w[0] > w[1]),
            "datagrams overtake each other"
        );
        assert!(d.iter().enumerate().all(|(i, t)| {
            let sent = i as u64 * 100;
            (sent + 1_000..=sent + 6_000).contains(t)
        }));
    }

    #[test]
    fn loss_duplication_and_cuts_happen_at_their_rates_and_times() {
        let model = LinkModel {
            duplicate: 0.2,
            cuts: vec![(100, Some(200))],
            ..LinkModel::default()
        };
        let mut l = Link::new(model, 0.3, 11, false);
        let fates: Vec<Sent> = (0..10_000u64).map(|i| l.send(300_000 + i)).collect();
        let lost = fates.iter().filter(|s| s.fate == Fate::Lost).count();
        let dup = fates.iter().filter(|s| s.at_us.len() == 2).count();
        // 4 sigma of the binomial spread.
        assert!((3000i64 - lost as i64).abs() < 4 * 46, "{lost} lost");
        assert!((1400i64 - dup as i64).abs() < 4 * 35, "{dup} duplicated");
        assert_eq!(l.send(150_000).fate, Fate::Cut);
        assert_ne!(
            l.send(99_999).fate,
            Fate::Cut,
            "99.999 ms is before the cut"
        );
        assert_ne!(l.send(200_000).fate, Fate::Cut);
    }

    #[test]
    fn the_same_seed_gives_the_same_fates_and_another_seed_others() {
        let model = LinkModel {
            jitter_us: 3_000,
            duplicate: 0.1,
            reorder: 0.1,
            reorder_us: 10_000,
            ..LinkModel::default()
        };
        let run = |seed| {
            let mut l = Link::new(model.clone(), 0.2, seed, true);
            (0..500u64).map(|i| l.send(i * 1000)).collect::<Vec<_>>()
        };
        assert_eq!(run(5), run(5));
        assert_ne!(run(5), run(6));
    }
}
