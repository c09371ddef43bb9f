//! spec/hardware.toml, the paper's hardware facts: it parses, every entry quotes the paper, every
//! departure names a recorded decision, and each number the code has a counterpart for equals
//! it. The bolter statistics test (tests/control/bolter_statistics.rs) reads Figure 10's counts
//! from the same file, with the toml crate's table rather than these types.

use mmic::bolter::{BolterPair, Config as BolterConfig};
use mmic::safety::detect::Config as SafetyConfig;
use mmic::sensors::adc::{Channel, CODE_MAX};
use mmic::sensors::frontend::WINDOW;
use serde::Deserialize;
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(crate::ROOT)
}

fn text(rel: &str) -> String {
    let p = root().join(rel);
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Hardware {
    battery: Battery,
    regulator: toml::Table,
    board: toml::Table,
    cores: toml::Table,
    server_board: toml::Table,
    imu: Part,
    adc: Adc,
    mux: Mux,
    face: Face,
    hip_encoder: toml::Table,
    filter: Filter,
    figure10: Figure10,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Battery {
    paper: String,
    count: u32,
    capacity_mah: u32,
    #[allow(dead_code)]
    chemistry: String,
    connection: String,
    min_mv: u16,
    max_mv: u16,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Part {
    #[allow(dead_code)]
    paper: String,
    part: String,
    driver: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Adc {
    #[allow(dead_code)]
    paper: String,
    part: String,
    channels: usize,
    bits: u32,
    driver: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Mux {
    #[allow(dead_code)]
    paper: String,
    #[allow(dead_code)]
    part: String,
    channels: usize,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Face {
    #[allow(dead_code)]
    paper: String,
    fasteners: usize,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Filter {
    #[allow(dead_code)]
    paper: String,
    window: usize,
}

/// Figure 10, in fastener pairs (spec/decisions.toml, `figure-10-pairs`).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Figure10 {
    paper: String,
    engaged: u32,
    bolted_after_attempt: Vec<u32>,
    failed: u32,
    #[allow(dead_code)]
    counts: String,
    #[allow(dead_code)]
    decision: String,
}

impl Figure10 {
    /// The histogram of Figure 10: bolted after attempt 1, 2, 3, then failed.
    fn histogram(&self) -> Vec<u32> {
        let mut h = self.bolted_after_attempt.clone();
        h.push(self.failed);
        h
    }
}

fn hardware() -> Hardware {
    toml::from_str(&text("spec/hardware.toml")).unwrap()
}

/// Figure 10's counts as spec/hardware.toml gives them.
fn figure10() -> Figure10 {
    hardware().figure10
}

/// Every table quotes the paper, word for word, in its `paper` entry: each quoted sentence
/// (the `[...]` cuts and section notes aside) is in the paper's text, so a number typed here is
/// the paper's.
// req: D:firmware-chips
#[test]
fn every_entry_quotes_the_paper_and_every_departure_is_a_decision() {
    let raw: toml::Table = toml::from_str(&text("spec/hardware.toml")).unwrap();
    let paper_file = root().join("../shared/reference/mmic-i-firmware-paper.txt");
    let paper = std::fs::read_to_string(&paper_file).ok();
    let decisions: toml::Table = toml::from_str(&text("spec/decisions.toml")).unwrap();
    let ids: Vec<&str> = decisions["decision"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| d["id"].as_str().unwrap())
        .collect();
    let mut tables: Vec<(String, &toml::Table)> = Vec::new();
    for (k, v) in &raw {
        let t = v.as_table().unwrap();
        tables.push((k.clone(), t));
        for (k2, v2) in t {
            // A sub-table with its own quote ([board.connectors]); inline tables are values.
            if let Some(sub) = v2.as_table().filter(|s| s.contains_key("paper")) {
                tables.push((format!("{k}.{k2}"), sub));
            }
        }
    }
    assert_eq!(tables.len(), 13);
    for (name, t) in tables {
        let quote = t.get("paper").and_then(|p| p.as_str());
        let quote = quote.unwrap_or_else(|| panic!("[{name}] quotes no paper"));
        if let Some(decision) = t.get("decision") {
            let id = decision.as_str().unwrap();
            assert!(ids.contains(&id), "[{name}]: no decision {id}");
        }
        // The paper's text is beside the repository on the development machines (not in CI's
        // clone): where it is, every fragment of the quote must be in it.
        let Some(paper) = &paper else { continue };
        let squash = |s: &str| s.split_whitespace().collect::<Vec<_>>().join(" ");
        let paper = squash(paper);
        for part in quote.split("[...]") {
            for sentence in part.split(['(', ')', '\'']) {
                let s = squash(sentence.trim().trim_matches(['.', ':', ' ']));
                let note = ["Section", "Reference", "Table"]
                    .iter()
                    .any(|n| s.starts_with(n));
                if s.len() < 12 || note {
                    continue;
                }
                assert!(paper.contains(&s), "[{name}]: not in the paper: {s:?}");
            }
        }
    }
}

// req: P2.1, P2.10
#[test]
fn the_codes_numbers_equal_the_papers_hardware() {
    let h = hardware();
    // Two batteries in parallel: the voltage range is one battery's. Its floor is the
    // low-battery threshold of Table 8 (spec/modes.toml), as the paper says.
    assert_eq!(
        (h.battery.count, h.battery.connection.as_str()),
        (2, "parallel")
    );
    let two = format!("two {} mAh", h.battery.capacity_mah);
    assert!(h.battery.paper.contains(&two), "{two}");
    assert_eq!(SafetyConfig::default().low_battery_mv, h.battery.min_mv);
    #[derive(Deserialize)]
    struct Modes {
        thresholds: Thresholds,
    }
    #[derive(Deserialize)]
    struct Thresholds {
        low_battery_mv: u16,
    }
    let modes: Modes = toml::from_str(&text("spec/modes.toml")).unwrap();
    assert_eq!(modes.thresholds.low_battery_mv, h.battery.min_mv);
    assert!(h.battery.min_mv < h.battery.max_mv);
    assert_eq!(h.regulator["output_mv"].as_integer(), Some(7400));
    assert_eq!(h.board["layers"].as_integer(), Some(8));
    assert_eq!(h.board["cores"].as_integer(), Some(2));
    assert_eq!(h.board["module"].as_str(), Some("ESP32-WROOM-32E"));
    assert!(h.cores["board_a"].as_table().is_some_and(|t| t.len() == 2));
    assert!(h.server_board["module"].as_str().is_some());
    assert_eq!(h.hip_encoder["board"].as_str(), Some("A"));

    // The ADC: eight channels of 12 bits.
    assert_eq!(Channel::ALL.len(), h.adc.channels);
    assert_eq!(u32::from(CODE_MAX) + 1, 1 << h.adc.bits);
    // Four bolter pairs, one per multiplexer channel and per fastener of a face.
    assert_eq!(BolterPair::ALL.len(), h.mux.channels);
    assert_eq!(BolterPair::ALL.len(), h.face.fasteners);
    // Section 2's moving average.
    assert_eq!(WINDOW, h.filter.window);
    // The firmware drives these parts: each driver's first line names its part.
    for (part, driver) in [(&h.imu.part, &h.imu.driver), (&h.adc.part, &h.adc.driver)] {
        let first = text(driver);
        let first = first.lines().next().unwrap_or_default();
        assert!(first.contains(part.as_str()), "{driver}: {first}");
    }
}

/// Figure 10's counts add up, one per attempt Table 8 allows; the statistics test draws its
/// rates from them (`control::bolter_statistics::attempt_histogram_matches_figure_10`, in the
/// library's test binary).
// req: P8.1
#[test]
fn figure_10_counts_add_up_to_the_pairs_engaged_one_count_per_attempt() {
    let f = figure10();
    assert_eq!(f.histogram().iter().sum::<u32>(), f.engaged);
    // Each count is one the paper's sentence gives, in its order.
    let words: Vec<u32> = f
        .paper
        .split(|c: char| !c.is_ascii_digit())
        .filter_map(|w| w.parse().ok())
        .collect();
    let mut want = vec![f.engaged];
    want.extend(f.histogram());
    assert_eq!(words, want);
    let attempts = usize::from(BolterConfig::default().max_attempts);
    assert_eq!(f.bolted_after_attempt.len(), attempts);
    assert_eq!(
        usize::from(SafetyConfig::default().bolting_max_attempts),
        attempts
    );
}
