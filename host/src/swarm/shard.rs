//! `mmic swarm --shard K/N` and `mmic swarm --merge`: one campaign of seeds over N machines.
//!
//! A campaign is a fixed range of seeds (`--seed-start S --runs R`: the seeds S..S+R), never a
//! wall-clock budget, whose seed set would depend on each machine's speed. Shard K of N runs
//! the seeds whose offset in the range is K-1 modulo N: interleaved rather than in blocks, so
//! that each shard gets its share of every part of the range (seeds drawn slow or fast are
//! spread evenly, and a shard stopped early still covers the whole range sparsely). The shards
//! of one N are disjoint and together they are the range ([`Shard::seeds`]).
//!
//! Each shard's JSON report says which shard it is, the campaign's options, and how many seeds
//! it ran with an order-free digest of them ([`SeedDigest`]); [`merge`] checks that the reports
//! are the N shards of one campaign, each once, and adds them up into the report the single run
//! would have written (every field but the wall-clock ones).
//!
//! ```
//! use mmic_host::swarm::shard::{SeedRange, Shard};
//! let range = SeedRange::new(1, 10).unwrap();
//! let shard: Shard = "2/3".parse().unwrap();
//! assert_eq!(shard.seeds(range).collect::<Vec<_>>(), [2, 5, 8]);
//! assert_eq!(shard.share(range), 3);
//! assert_eq!("0/4".parse::<Shard>().unwrap_err().to_string(), "0/4: K must be 1..=4");
//! ```

use serde_json::{Map, Value};
use std::collections::BTreeMap;
use std::str::FromStr;

/// Why `--shard` or a seed range was refused.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ShardError {
    /// Not two whole numbers around a slash.
    #[error("{found:?}: expected K/N (shard K of N machines, whole numbers, 1 <= K <= N)")]
    Syntax {
        /// What was given.
        found: String,
    },
    /// N is 0.
    #[error("{k}/0: N must be at least 1")]
    NoShards {
        /// The K given.
        k: u32,
    },
    /// K is 0 or beyond N.
    #[error("{k}/{n}: K must be 1..={n}")]
    KOutOfRange {
        /// The K given.
        k: u32,
        /// The N given.
        n: u32,
    },
    /// The range passes the last seed.
    #[error(
        "--seed-start {start} --runs {runs}: the seeds would pass {}",
        u64::MAX
    )]
    RangeOverflow {
        /// The first seed.
        start: u64,
        /// How many.
        runs: u64,
    },
}

/// Shard K of N: 1 <= K <= N.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Shard {
    k: u32,
    n: u32,
}

/// A campaign's seeds: `start`, `start + 1`, ..., `start + runs - 1`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SeedRange {
    start: u64,
    runs: u64,
}

impl SeedRange {
    /// The `runs` seeds from `start`; refused if they would pass `u64::MAX`.
    pub fn new(start: u64, runs: u64) -> Result<SeedRange, ShardError> {
        match start.checked_add(runs) {
            Some(_) => Ok(SeedRange { start, runs }),
            None => Err(ShardError::RangeOverflow { start, runs }),
        }
    }

    /// The first seed.
    pub fn start(self) -> u64 {
        self.start
    }

    /// How many seeds.
    pub fn runs(self) -> u64 {
        self.runs
    }

    /// Every seed, ascending.
    pub fn seeds(self) -> std::ops::Range<u64> {
        // No overflow: checked in `new`.
        self.start..self.start + self.runs
    }
}

impl Shard {
    /// Shard `k` of `n`.
    pub fn new(k: u32, n: u32) -> Result<Shard, ShardError> {
        if n == 0 {
            Err(ShardError::NoShards { k })
        } else if k == 0 || k > n {
            Err(ShardError::KOutOfRange { k, n })
        } else {
            Ok(Shard { k, n })
        }
    }

    /// K, 1-based.
    pub fn k(self) -> u32 {
        self.k
    }

    /// N.
    pub fn n(self) -> u32 {
        self.n
    }

    /// This shard's seeds in `range`, ascending: those whose offset from the range's start is
    /// K-1 modulo N.
    pub fn seeds(self, range: SeedRange) -> impl Iterator<Item = u64> {
        let first = range.start.saturating_add(u64::from(self.k - 1));
        let step = usize::try_from(self.n).unwrap_or(usize::MAX);
        (first.min(range.start + range.runs)..range.start + range.runs).step_by(step)
    }

    /// How many seeds of `range` are this shard's.
    pub fn share(self, range: SeedRange) -> u64 {
        range
            .runs
            .saturating_sub(u64::from(self.k - 1))
            .div_ceil(u64::from(self.n))
    }

    /// The shard of `n` that runs `seed` of `range` (none if the seed is not in it).
    pub fn of(range: SeedRange, n: u32, seed: u64) -> Option<Shard> {
        let offset = seed.checked_sub(range.start).filter(|o| *o < range.runs)?;
        let k = u32::try_from(offset % u64::from(n.max(1))).ok()? + 1;
        Shard::new(k, n).ok()
    }
}

impl FromStr for Shard {
    type Err = ShardError;

    fn from_str(s: &str) -> Result<Shard, ShardError> {
        let syntax = || ShardError::Syntax {
            found: s.to_string(),
        };
        let (k, n) = s.split_once('/').ok_or_else(syntax)?;
        let number = |t: &str| {
            if t.is_empty() || !t.bytes().all(|b| b.is_ascii_digit()) {
                return Err(syntax());
            }
            t.parse::<u32>().map_err(|_| syntax())
        };
        Shard::new(number(k)?, number(n)?)
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.k, self.n)
    }
}

/// An order-free digest of a set of seeds: the wrapping sum of each seed's SplitMix64 mix. The
/// digest of a union of disjoint sets is the sum of theirs, so the merged shards' digest is the
/// single run's exactly when they ran the same seeds (up to a 64-bit collision); a seed run
/// twice, or one missing, changes it. It identifies, it does not authenticate.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SeedDigest {
    count: u64,
    sum: u64,
}

impl SeedDigest {
    /// Adds one seed.
    pub fn add(&mut self, seed: u64) {
        self.count += 1;
        self.sum = self.sum.wrapping_add(mix(seed));
    }

    /// Both sets together (disjoint).
    pub fn merged(self, o: SeedDigest) -> SeedDigest {
        SeedDigest {
            count: self.count + o.count,
            sum: self.sum.wrapping_add(o.sum),
        }
    }

    /// The digest of `seeds`.
    pub fn of(seeds: impl IntoIterator<Item = u64>) -> SeedDigest {
        let mut d = SeedDigest::default();
        seeds.into_iter().for_each(|s| d.add(s));
        d
    }

    /// How many seeds.
    pub fn count(self) -> u64 {
        self.count
    }

    /// The JSON form: `{"count": n, "digest": "16 hex digits"}`.
    pub fn json(self) -> Value {
        serde_json::json!({ "count": self.count, "digest": format!("{:016x}", self.sum) })
    }

    fn from_json(v: &Value) -> Option<SeedDigest> {
        let count = v["count"].as_u64()?;
        let sum = u64::from_str_radix(v["digest"].as_str()?, 16).ok()?;
        Some(SeedDigest { count, sum })
    }
}

/// SplitMix64's finaliser: a bijection of u64 that spreads neighbouring seeds apart.
fn mix(seed: u64) -> u64 {
    let mut z = seed.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The JSON `options` of a swarm report: what decides which seeds run and what each one's
/// scenario and verdict are. Shards of one campaign must agree on all of them.
pub const OPTION_FLAGS: [(&str, &str); 7] = [
    ("seed_start", "--seed-start"),
    ("runs", "--runs"),
    ("sim_seconds", "--sim-seconds"),
    ("link", "--link"),
    ("sdls", "--sdls"),
    ("restarts", "--restarts"),
    ("plant_bug", "--plant-bug"),
];

/// Why shard reports were not merged.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum MergeError {
    /// Nothing to merge.
    #[error("no shard reports to merge")]
    Empty,
    /// A report that is not a shard's (no `shard`, or a field missing or malformed).
    #[error("{file}: not a shard report of `mmic swarm --shard K/N --json`: {why}")]
    NotAShard {
        /// The report.
        file: String,
        /// What is missing or malformed.
        why: String,
    },
    /// Two reports from different campaigns.
    #[error(
        "{file}: {flag} {found}, but {first}'s is {expected}: shards of one campaign share \
         every option"
    )]
    Mismatch {
        /// The report that differs.
        file: String,
        /// The option, as its flag (`--sim-seconds`; `--shard N` for the number of shards).
        flag: String,
        /// Its value there.
        found: String,
        /// The first report.
        first: String,
        /// Its value in the first report.
        expected: String,
    },
    /// The same shard twice: its seeds would count twice.
    #[error("{file} and {other} are both shard {shard}: its {seeds} seeds would be counted twice")]
    Overlap {
        /// The later report.
        file: String,
        /// The earlier one.
        other: String,
        /// The shard.
        shard: Shard,
        /// How many seeds the later one ran.
        seeds: u64,
    },
    /// Shards missing: their seeds would be missing from the campaign.
    #[error("shard {missing} of {n} missing ({seeds} seeds not covered); given: {given}")]
    Missing {
        /// The missing K, as ranges (`2, 5-7`).
        missing: String,
        /// N.
        n: u32,
        /// How many seeds of the range those shards hold.
        seeds: u64,
        /// The K given, as ranges.
        given: String,
    },
    /// A report whose seeds are not its shard's.
    #[error(
        "{file}: shard {shard} ran {count} seeds with digest {found}, but the first {count} \
         seeds of its share (of {share}) give {expected}"
    )]
    Seeds {
        /// The report.
        file: String,
        /// Its shard.
        shard: Shard,
        /// How many seeds it says it ran.
        count: u64,
        /// Its share of the range.
        share: u64,
        /// The digest it gives.
        found: String,
        /// The digest of those seeds.
        expected: String,
    },
    /// A figure that cannot be added (not a count).
    #[error("{file}: {field}: cannot add {a} and {b} (only counts add up)")]
    Field {
        /// The report.
        file: String,
        /// The field's path.
        field: String,
        /// The sum so far.
        a: String,
        /// This report's value.
        b: String,
    },
}

/// The fields of a report that [`merge`] does not add up: it checks or recomputes them.
const NOT_ADDED: [&str; 8] = [
    "shard",
    "options",
    "seeds",
    "failures",
    "wall_s",
    "runs_per_second",
    "sim_hours",
    "merged",
];

/// `a + b` for a report's counters: numbers add (u64), objects add key by key (a key missing
/// on one side counts as absent), `null` is absent.
fn add(a: &Value, b: &Value, field: &str, file: &str) -> Result<Value, MergeError> {
    let refuse = || MergeError::Field {
        file: file.to_string(),
        field: field.to_string(),
        a: a.to_string(),
        b: b.to_string(),
    };
    Ok(match (a, b) {
        (Value::Null, x) | (x, Value::Null) => x.clone(),
        (Value::Number(x), Value::Number(y)) => {
            let (x, y) = (
                x.as_u64().ok_or_else(refuse)?,
                y.as_u64().ok_or_else(refuse)?,
            );
            Value::from(x.checked_add(y).ok_or_else(refuse)?)
        }
        (Value::Object(x), Value::Object(y)) => {
            let mut out = x.clone();
            for (k, v) in y {
                let sum = add(
                    x.get(k).unwrap_or(&Value::Null),
                    v,
                    &format!("{field}.{k}"),
                    file,
                )?;
                out.insert(k.clone(), sum);
            }
            Value::Object(out)
        }
        _ => return Err(refuse()),
    })
}

/// A JSON value as a flag's value: strings without their quotes.
fn bare(v: &Value) -> String {
    v.as_str().map_or_else(|| v.to_string(), str::to_string)
}

/// Whole numbers as ranges: `1-3, 5`.
fn ranges(ks: &[u32]) -> String {
    let mut out: Vec<String> = Vec::new();
    let mut i = 0;
    while i < ks.len() {
        let mut j = i;
        while j + 1 < ks.len() && ks[j + 1] == ks[j] + 1 {
            j += 1;
        }
        out.push(if j == i {
            ks[i].to_string()
        } else {
            format!("{}-{}", ks[i], ks[j])
        });
        i = j + 1;
    }
    if out.is_empty() {
        "none".into()
    } else {
        out.join(", ")
    }
}

/// One shard's report, checked.
struct Part<'a> {
    file: &'a str,
    shard: Shard,
    seeds: SeedDigest,
    report: &'a Map<String, Value>,
}

fn part<'a>(file: &'a str, v: &'a Value) -> Result<Part<'a>, MergeError> {
    let not = |why: &str| MergeError::NotAShard {
        file: file.to_string(),
        why: why.to_string(),
    };
    let report = v.as_object().ok_or_else(|| not("not a JSON object"))?;
    let s = report
        .get("shard")
        .ok_or_else(|| not("no \"shard\" (a single run's report?)"))?;
    let k = s["k"].as_u64().and_then(|k| u32::try_from(k).ok());
    let n = s["n"].as_u64().and_then(|n| u32::try_from(n).ok());
    let shard = match (k, n) {
        (Some(k), Some(n)) => Shard::new(k, n).map_err(|e| not(&format!("shard: {e}")))?,
        _ => return Err(not("\"shard\" has no whole k and n")),
    };
    let seeds = report
        .get("seeds")
        .and_then(SeedDigest::from_json)
        .ok_or_else(|| not("no \"seeds\" with a count and a hex digest"))?;
    let options = report
        .get("options")
        .and_then(Value::as_object)
        .ok_or_else(|| not("no \"options\""))?;
    for (key, _) in OPTION_FLAGS {
        if !options.contains_key(key) {
            return Err(not(&format!("no options.{key}")));
        }
    }
    if options["runs"].as_u64().is_none() || options["seed_start"].as_u64().is_none() {
        return Err(not(
            "options.runs and options.seed_start must be whole numbers",
        ));
    }
    Ok(Part {
        file,
        shard,
        seeds,
        report,
    })
}

/// Merges the JSON reports of a sharded campaign, given with their file names (for the
/// errors), into the report of the single run over the same seeds.
///
/// Refused: a report that is not a shard's, reports whose options or N differ, the same shard
/// twice, a shard missing (the error lists which K), a report whose seed count and digest are
/// not those of the first seeds of its share. A shard that stopped at its `--max-failures`
/// ran only the first seeds of its share: it is merged, and the merged report says how many
/// seeds of the range did not run (`merged.unrun`).
///
/// The merged report has every field of the single run's JSON with the same value — runs,
/// simulated ms and hours, plans completed, frame and SDLS figures, the invariants' checks,
/// the options, the seeds' count and digest, the failures in seed order with their replay
/// commands — but for the wall clock's: `wall_s` is the longest shard's, `machine_s` the sum of
/// all, and `runs_per_second` is runs per machine second. It adds `merged`: the number of
/// shards, whether every seed ran, and how many did not. (The single run stops at its own
/// `--max-failures` failing seeds, each shard at its own: their failures lists are the same
/// when the campaign has fewer failing seeds than that.)
pub fn merge(reports: &[(String, Value)]) -> Result<Value, MergeError> {
    let parts = reports
        .iter()
        .map(|(file, v)| part(file, v))
        .collect::<Result<Vec<_>, _>>()?;
    let first = parts.first().ok_or(MergeError::Empty)?;
    let options = &first.report["options"];
    let n = first.shard.n();
    let by_k = by_shard(&parts, first)?;
    // Checked in `part`: whole numbers.
    let range = SeedRange::new(
        options["seed_start"].as_u64().unwrap_or(0),
        options["runs"].as_u64().unwrap_or(0),
    )
    .map_err(|e| MergeError::NotAShard {
        file: first.file.to_string(),
        why: e.to_string(),
    })?;
    let missing: Vec<u32> = (1..=n).filter(|k| !by_k.contains_key(k)).collect();
    if !missing.is_empty() {
        let seeds = missing
            .iter()
            .filter_map(|&k| Shard::new(k, n).ok())
            .map(|s| s.share(range))
            .sum();
        return Err(MergeError::Missing {
            missing: ranges(&missing),
            n,
            seeds,
            given: ranges(&by_k.keys().copied().collect::<Vec<_>>()),
        });
    }
    let (seeds, unrun) = checked_seeds(&by_k, range)?;
    let mut out = Map::new();
    let (mut wall, mut machine) = (0.0f64, 0.0f64);
    let mut failures: Vec<Value> = Vec::new();
    for p in by_k.values() {
        for (key, v) in p.report {
            if NOT_ADDED.contains(&key.as_str()) {
                continue;
            }
            let sum = add(out.get(key).unwrap_or(&Value::Null), v, key, p.file)?;
            out.insert(key.clone(), sum);
        }
        let w = p
            .report
            .get("wall_s")
            .and_then(Value::as_f64)
            .unwrap_or(0.0);
        wall = wall.max(w);
        machine += w;
        if let Some(f) = p.report.get("failures").and_then(Value::as_array) {
            failures.extend(f.iter().cloned());
        }
    }
    failures.sort_by_key(|f| f["seed"].as_u64());
    let runs = out.get("runs").and_then(Value::as_u64).unwrap_or(0);
    let sim_ms = out.get("sim_ms").and_then(Value::as_u64).unwrap_or(0);
    out.insert("sim_hours".into(), Value::from(sim_ms as f64 / 3_600_000.0));
    out.insert("wall_s".into(), Value::from(wall));
    out.insert("machine_s".into(), Value::from(machine));
    out.insert(
        "runs_per_second".into(),
        Value::from(runs as f64 / machine.max(1e-9)),
    );
    out.insert("options".into(), options.clone());
    out.insert("seeds".into(), seeds.json());
    out.insert("failures".into(), Value::from(failures));
    out.insert(
        "merged".into(),
        serde_json::json!({ "shards": n, "complete": unrun == 0, "unrun": unrun }),
    );
    Ok(Value::Object(out))
}

/// The parts by shard number, each checked against the first: the same N and the same options,
/// no shard given twice.
fn by_shard<'p, 'a>(
    parts: &'p [Part<'a>],
    first: &Part<'a>,
) -> Result<BTreeMap<u32, &'p Part<'a>>, MergeError> {
    let options = &first.report["options"];
    let n = first.shard.n();
    let mut by_k: BTreeMap<u32, &Part> = BTreeMap::new();
    for p in parts {
        let mismatch = |flag: &str, found: String, expected: String| MergeError::Mismatch {
            file: p.file.to_string(),
            flag: flag.to_string(),
            found,
            first: first.file.to_string(),
            expected,
        };
        if p.shard.n() != n {
            return Err(mismatch(
                "--shard N",
                p.shard.n().to_string(),
                n.to_string(),
            ));
        }
        for (key, flag) in OPTION_FLAGS {
            let (found, expected) = (&p.report["options"][key], &options[key]);
            if found != expected {
                return Err(mismatch(flag, bare(found), bare(expected)));
            }
        }
        if let Some(other) = by_k.insert(p.shard.k(), p) {
            return Err(MergeError::Overlap {
                file: p.file.to_string(),
                other: other.file.to_string(),
                shard: p.shard,
                seeds: p.seeds.count(),
            });
        }
    }
    Ok(by_k)
}

/// Every shard ran a prefix of its own seeds (count and digest): the campaign's digest and
/// how many of its seeds did not run.
fn checked_seeds(
    by_k: &BTreeMap<u32, &Part<'_>>,
    range: SeedRange,
) -> Result<(SeedDigest, u64), MergeError> {
    let mut seeds = SeedDigest::default();
    let mut unrun = 0;
    for p in by_k.values() {
        let share = p.shard.share(range);
        let expected = SeedDigest::of(
            p.shard
                .seeds(range)
                .take(usize::try_from(p.seeds.count()).unwrap_or(usize::MAX)),
        );
        if p.seeds.count() > share || expected != p.seeds {
            return Err(MergeError::Seeds {
                file: p.file.to_string(),
                shard: p.shard,
                count: p.seeds.count(),
                share,
                found: p.report["seeds"]["digest"].to_string(),
                expected: format!("{:016x}", expected.sum),
            });
        }
        unrun += share - p.seeds.count();
        seeds = seeds.merged(p.seeds);
    }
    Ok((seeds, unrun))
}

/// The merged report as text: the campaign, its figures, and each failure with its replay.
pub fn merged_text(v: &Value) -> String {
    let o = &v["options"];
    let c = &v["checked"];
    let n = |x: &Value| x.as_u64().unwrap_or(0);
    let mut t = format!(
        "swarm merge: {} shards of the {} seeds from {} (--sim-seconds {}, --link {}, --sdls {}, \
         --restarts {}, --plant-bug {}): {} runs, {:.2} simulated hours, {:.1} machine seconds (longest shard \
         {:.1} s); {} plans completed, {} ended otherwise\n\
         checked: {} admissions, {} board A ticks in motion, {} ticks in Standby, {} faults \
         raised, {} commands ended, {} injected faults expected in time, {} attack frames\n\
         space data link: {} runs over frames, {} with SDLS, {} attacked\n\
         restarts: {} runs with a node restarting; commands executed twice: {}\n\
         seeds: {} run, digest {}\n",
        n(&v["merged"]["shards"]),
        n(&o["runs"]),
        n(&o["seed_start"]),
        n(&o["sim_seconds"]),
        o["link"].as_str().unwrap_or("?"),
        o["sdls"].as_str().unwrap_or("?"),
        o["restarts"].as_str().unwrap_or("?"),
        o["plant_bug"].as_str().unwrap_or("?"),
        n(&v["runs"]),
        v["sim_hours"].as_f64().unwrap_or(0.0),
        v["machine_s"].as_f64().unwrap_or(0.0),
        v["wall_s"].as_f64().unwrap_or(0.0),
        n(&v["completed"]),
        n(&v["runs"]).saturating_sub(n(&v["completed"])),
        n(&c["admissions"]),
        n(&c["motion_ticks"]),
        n(&c["standby_ticks"]),
        n(&c["faults_raised"]),
        n(&c["commands_ended"]),
        n(&c["injected_faults_raised"]),
        n(&c["attack_frames"]),
        n(&v["frame_runs"]),
        n(&v["sdls_runs"]),
        n(&v["attacked_runs"]),
        n(&v["restart_runs"]),
        n(&v["executed_twice"]),
        n(&v["seeds"]["count"]),
        v["seeds"]["digest"].as_str().unwrap_or("?"),
    );
    let unrun = n(&v["merged"]["unrun"]);
    if unrun > 0 {
        t.push_str(&format!(
            "incomplete: {unrun} seeds not run (a shard stopped at its --max-failures)\n"
        ));
    }
    let failures = v["failures"].as_array().map(Vec::as_slice).unwrap_or(&[]);
    if failures.is_empty() {
        t.push_str("result: no invariant broken\n");
    }
    for f in failures {
        t.push_str(&format!(
            "FAILED {}\n",
            f["scenario"].as_str().unwrap_or("?")
        ));
        for x in f["violations"].as_array().map(Vec::as_slice).unwrap_or(&[]) {
            t.push_str(&format!(
                "  {} at {} ms: {}\n",
                x["invariant"].as_str().unwrap_or("?"),
                n(&x["t_ms"]),
                x["detail"].as_str().unwrap_or("?"),
            ));
        }
        t.push_str(&format!(
            "  replay: {}\n",
            f["replay"].as_str().unwrap_or("?")
        ));
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    /// For several range lengths and shard counts (more shards than seeds among them), the
    /// shards are disjoint, together they are the range, each in ascending order, their
    /// shares as counted, balanced to one seed, and `Shard::of` names each seed's shard.
    #[test]
    fn the_shards_of_a_range_partition_it() {
        for start in [0, 1, 5_000, u64::MAX - 40] {
            for runs in [0, 1, 2, 7, 24, 25, 40] {
                let range = SeedRange::new(start, runs).unwrap();
                for n in [1, 2, 3, 4, 7, 24, 50] {
                    let mut seen = std::collections::BTreeMap::new();
                    let mut shares = Vec::new();
                    for k in 1..=n {
                        let shard = Shard::new(k, n).unwrap();
                        let seeds: Vec<u64> = shard.seeds(range).collect();
                        assert!(seeds.windows(2).all(|w| w[0] + u64::from(n) == w[1]));
                        assert_eq!(seeds.len() as u64, shard.share(range), "{shard} of {runs}");
                        shares.push(seeds.len());
                        for s in seeds {
                            assert_eq!(Shard::of(range, n, s), Some(shard));
                            assert!(seen.insert(s, k).is_none(), "seed {s} in two shards");
                        }
                    }
                    let all: Vec<u64> = seen.keys().copied().collect();
                    assert_eq!(all, range.seeds().collect::<Vec<_>>(), "{runs} seeds, {n}");
                    let (min, max) = (shares.iter().min(), shares.iter().max());
                    assert!(max.unwrap() - min.unwrap() <= 1, "{shares:?}");
                    let digests = (1..=n)
                        .map(|k| SeedDigest::of(Shard::new(k, n).unwrap().seeds(range)))
                        .fold(SeedDigest::default(), SeedDigest::merged);
                    assert_eq!(digests, SeedDigest::of(range.seeds()));
                }
            }
        }
        assert_eq!(Shard::of(SeedRange::new(10, 5).unwrap(), 2, 9), None);
        assert_eq!(Shard::of(SeedRange::new(10, 5).unwrap(), 2, 15), None);
    }

    #[test]
    fn a_shard_is_parsed_and_refused_with_what_was_expected() {
        assert_eq!("3/4".parse(), Shard::new(3, 4));
        assert_eq!("1/1".parse::<Shard>().unwrap().to_string(), "1/1");
        for (s, e) in [
            ("0/4", "0/4: K must be 1..=4"),
            ("5/4", "5/4: K must be 1..=4"),
            ("1/0", "1/0: N must be at least 1"),
            (
                "3",
                "\"3\": expected K/N (shard K of N machines, whole numbers, 1 <= K <= N)",
            ),
        ] {
            assert_eq!(s.parse::<Shard>().unwrap_err().to_string(), e);
        }
        for s in [
            "",
            "/",
            "1/",
            "/2",
            "-1/2",
            "+1/2",
            "1/2/3",
            " 1/2",
            "a/b",
            "1/99999999999",
        ] {
            assert!(
                matches!(s.parse::<Shard>(), Err(ShardError::Syntax { .. })),
                "{s:?}"
            );
        }
        assert_eq!(
            SeedRange::new(u64::MAX - 1, 2),
            Err(ShardError::RangeOverflow {
                start: u64::MAX - 1,
                runs: 2
            })
        );
        assert!(SeedRange::new(u64::MAX - 1, 1).is_ok());
    }

    #[test]
    fn a_seed_twice_or_a_seed_swapped_changes_the_digest() {
        let d = SeedDigest::of(1..=24);
        assert_ne!(SeedDigest::of((1..=24).chain([5])), d);
        assert_ne!(SeedDigest::of((1..=23).chain([25])), d);
        assert_eq!(SeedDigest::of((1..=24).rev()), d);
        assert_eq!(SeedDigest::from_json(&d.json()), Some(d));
    }

    #[test]
    fn counters_add_key_by_key_and_nothing_else_adds() {
        let a = serde_json::json!({"x": 1, "o": {"p": 2}, "s": null});
        let b = serde_json::json!({"x": 2, "o": {"p": 3, "q": 4}, "s": {"z": 1}});
        assert_eq!(
            add(&a, &b, "f", "b.json").unwrap(),
            serde_json::json!({"x": 3, "o": {"p": 5, "q": 4}, "s": {"z": 1}})
        );
        for (a, b) in [
            (serde_json::json!(1.5), serde_json::json!(1)),
            (serde_json::json!("any"), serde_json::json!("any")),
            (serde_json::json!(u64::MAX), serde_json::json!(1)),
            (serde_json::json!([1]), serde_json::json!([2])),
        ] {
            assert!(
                matches!(add(&a, &b, "f", "b.json"), Err(MergeError::Field { .. })),
                "{a} + {b}"
            );
        }
        assert_eq!(ranges(&[1, 2, 3, 5, 7, 8]), "1-3, 5, 7-8");
        assert_eq!(ranges(&[]), "none");
    }
}
