//! The swarm beyond one machine (issue 29): `mmic swarm --shard K/N` runs a fixed share of a
//! campaign's seeds, and `mmic swarm --merge` adds the shards' reports up into the single run's.

use mmic_host::swarm::shard::{merge, MergeError, SeedDigest, SeedRange, Shard};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn mmic(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mmic"))
        .args(args)
        .output()
        .unwrap()
}

fn dir(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn read(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The report without its wall-clock figures and the merge's own field: what the single run and
/// the merged shards must agree on.
fn deterministic(v: &Value) -> Value {
    let mut v = v.clone();
    let o = v.as_object_mut().unwrap();
    for k in ["wall_s", "runs_per_second", "machine_s", "merged"] {
        o.remove(k);
    }
    v
}

/// Runs shard K of `n` of the campaign `args` for every K; returns each report's file and JSON.
fn shards(d: &Path, args: &[&str], n: u32) -> Vec<(String, Value)> {
    (1..=n)
        .map(|k| {
            let file = d.join(format!("shard-{k}.json"));
            let shard = format!("{k}/{n}");
            let f = file.to_string_lossy().to_string();
            let mut a = vec!["swarm", "--shard", &shard, "--json", &f];
            a.extend(args);
            let out = mmic(&a);
            let v = read(&file);
            let failed = !v["failures"].as_array().unwrap().is_empty();
            assert_eq!(out.status.code(), Some(i32::from(failed)), "{out:?}");
            let err = String::from_utf8_lossy(&out.stderr);
            assert!(err.starts_with(&format!("swarm: shard {shard}: ")), "{err}");
            (f, v)
        })
        .collect()
}

#[test]
#[cfg_attr(miri, ignore = "runs the mmic binary")]
fn the_shards_of_a_campaign_run_its_seeds_once_and_merge_into_the_single_runs_report() {
    let range = SeedRange::new(1, 24).unwrap();
    // The shares: disjoint, and together the range.
    let mut all: Vec<u64> = (1..=3)
        .flat_map(|k| Shard::new(k, 3).unwrap().seeds(range))
        .collect();
    all.sort_unstable();
    assert_eq!(all, (1..=24).collect::<Vec<_>>());
    // A clean campaign, and one with the planted bug: failing seeds in every shard, each listed
    // with its replay command (--max-failures above the range: no run stops early).
    for bug in ["none", "double-exec"] {
        let d = dir(&format!("swarm-shard-{bug}"));
        let args = [
            "--runs",
            "24",
            "--sim-seconds",
            "20",
            "--plant-bug",
            bug,
            "--max-failures",
            "24",
        ];
        let single_file = d.join("single.json");
        let mut a = vec!["swarm", "--seconds", "600", "--json"];
        let f = single_file.to_string_lossy().to_string();
        a.push(&f);
        a.extend(args);
        let out = mmic(&a);
        let single = read(&single_file);
        let failures = single["failures"].as_array().unwrap().clone();
        assert_eq!(out.status.code(), Some(i32::from(!failures.is_empty())));
        assert_eq!(single["runs"], 24);
        assert_eq!(single["seeds"], SeedDigest::of(range.seeds()).json());
        assert_eq!(failures.is_empty(), bug == "none", "{failures:?}");

        let parts = shards(&d, &args, 3);
        let mut union = SeedDigest::default();
        for (file, v) in &parts {
            let k = v["shard"]["k"].as_u64().unwrap() as u32;
            let shard = Shard::new(k, 3).unwrap();
            // Each shard ran exactly its share (the digest is of the seeds it took to run).
            let own = SeedDigest::of(shard.seeds(range));
            assert_eq!(v["seeds"], own.json(), "{file}");
            assert_eq!(v["shard"]["share"], 8);
            assert_eq!(v["shard"]["complete"], true);
            assert_eq!(v["options"], single["options"]);
            for f in v["failures"].as_array().unwrap() {
                let seed = f["seed"].as_u64().unwrap();
                assert_eq!(
                    Shard::of(range, 3, seed),
                    Some(shard),
                    "{file}: seed {seed}"
                );
            }
            union = union.merged(own);
        }
        // The union of the shards' seeds is the single run's, no seed twice.
        assert_eq!(union, SeedDigest::of(range.seeds()));
        assert_eq!(union.count(), 24);
        if bug == "double-exec" {
            // The failures are spread over more than one shard.
            let with = parts
                .iter()
                .filter(|(_, v)| !v["failures"].as_array().unwrap().is_empty())
                .count();
            assert!(with >= 2, "{with} shards found failures");
        }

        // `mmic swarm --merge`, the shards given in any order.
        let merged_file = d.join("merged.json");
        let m = merged_file.to_string_lossy().to_string();
        let (f1, f2, f3) = (&parts[0].0, &parts[1].0, &parts[2].0);
        let out = mmic(&["swarm", "--merge", f3, f1, f2, "--json", &m]);
        assert_eq!(out.status.code(), Some(i32::from(!failures.is_empty())));
        let merged = read(&merged_file);
        assert_eq!(deterministic(&merged), deterministic(&single));
        assert_eq!(
            merged["merged"],
            serde_json::json!({"shards": 3, "complete": true, "unrun": 0})
        );
        let machine: f64 = parts
            .iter()
            .map(|(_, v)| v["wall_s"].as_f64().unwrap())
            .sum();
        assert!((merged["machine_s"].as_f64().unwrap() - machine).abs() < 1e-9);
        // The library's merge is the command's (through JSON text, as the file went: serde_json
        // reads a float back to within an ulp of what it wrote, not always to the same f64).
        let lib: Value = serde_json::from_str(&merge(&parts).unwrap().to_string()).unwrap();
        assert_eq!(lib, merged);
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(
            text.starts_with("swarm merge: 3 shards of the 24 seeds from 1 "),
            "{text}"
        );
        for f in &failures {
            let replay = format!("  replay: {}\n", f["replay"].as_str().unwrap());
            assert!(text.contains(&replay), "{replay} not in\n{text}");
        }
        if failures.is_empty() {
            assert!(text.contains("result: no invariant broken"), "{text}");
        }
    }
}

#[test]
#[cfg_attr(miri, ignore = "runs the mmic binary")]
fn merge_refuses_a_missing_shard_a_shard_twice_and_mismatched_shards() {
    let d = dir("swarm-shard-refusals");
    let args = ["--runs", "12", "--sim-seconds", "10"];
    let parts = shards(&d, &args, 3);
    let (s1, s2, s3) = (&parts[0], &parts[1], &parts[2]);
    assert!(merge(&parts).is_ok());

    let e = merge(&[s1.clone(), s3.clone()]).unwrap_err();
    assert!(
        matches!(&e, MergeError::Missing { missing, n: 3, seeds: 4, .. } if missing == "2"),
        "{e:?}"
    );
    let out = mmic(&["swarm", "--merge", &s1.0, &s3.0]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("shard 2 of 3 missing (4 seeds not covered)"),
        "{err}"
    );

    let e = merge(&[s1.clone(), s2.clone(), s3.clone(), s2.clone()]).unwrap_err();
    assert!(
        matches!(&e, MergeError::Overlap { shard, seeds: 4, .. } if shard.k() == 2),
        "{e:?}"
    );
    let out = mmic(&["swarm", "--merge", &s1.0, &s2.0, &s2.0, &s3.0]);
    assert_eq!(out.status.code(), Some(2));

    // Every option of the campaign must agree.
    for (key, flag, value) in [
        ("seed_start", "--seed-start", serde_json::json!(2)),
        ("runs", "--runs", serde_json::json!(13)),
        ("sim_seconds", "--sim-seconds", serde_json::json!(11)),
        ("link", "--link", serde_json::json!("frames")),
        ("sdls", "--sdls", serde_json::json!("on")),
        ("plant_bug", "--plant-bug", serde_json::json!("double-exec")),
    ] {
        let mut other = s2.clone();
        other.1["options"][key] = value;
        let e = merge(&[s1.clone(), other, s3.clone()]).unwrap_err();
        assert!(
            matches!(&e, MergeError::Mismatch { flag: f, .. } if f == flag),
            "{e:?}"
        );
    }
    // ... as run: shard 2 with other simulated seconds, or shard 2 of 4.
    let other = d.join("other.json");
    let o = other.to_string_lossy().to_string();
    for (shard, sim, flag) in [("2/3", "11", "--sim-seconds"), ("2/4", "10", "--shard N")] {
        let out = mmic(&[
            "swarm",
            "--shard",
            shard,
            "--runs",
            "12",
            "--sim-seconds",
            sim,
            "--json",
            &o,
        ]);
        assert_eq!(out.status.code(), Some(0), "{out:?}");
        let e = merge(&[s1.clone(), (o.clone(), read(&other)), s3.clone()]).unwrap_err();
        assert!(
            matches!(&e, MergeError::Mismatch { flag: f, .. } if f == flag),
            "{e:?}"
        );
        let out = mmic(&["swarm", "--merge", &s1.0, &o, &s3.0]);
        assert_eq!(out.status.code(), Some(2));
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(&format!("{o}: {flag} ")), "{err}");
    }
    // A report whose seeds are not its shard's, and a single run's report.
    let mut other = s2.clone();
    other.1["seeds"]["count"] = serde_json::json!(3);
    let e = merge(&[s1.clone(), other, s3.clone()]).unwrap_err();
    assert!(
        matches!(
            &e,
            MergeError::Seeds {
                count: 3,
                share: 4,
                ..
            }
        ),
        "{e:?}"
    );
    let mut single = s2.clone();
    single.1.as_object_mut().unwrap().remove("shard");
    let e = merge(&[s1.clone(), single, s3.clone()]).unwrap_err();
    assert!(matches!(&e, MergeError::NotAShard { .. }), "{e:?}");
    assert_eq!(merge(&[]).unwrap_err(), MergeError::Empty);
}

#[test]
#[cfg_attr(miri, ignore = "runs the mmic binary")]
fn a_shard_needs_a_fixed_range_and_a_shard_stopped_at_its_failures_is_merged_as_incomplete() {
    for (args, says) in [
        (
            vec!["--shard", "0/4", "--runs", "8"],
            "0/4: K must be 1..=4",
        ),
        (
            vec!["--shard", "5/4", "--runs", "8"],
            "5/4: K must be 1..=4",
        ),
        (
            vec!["--shard", "1/0", "--runs", "8"],
            "1/0: N must be at least 1",
        ),
        (vec!["--shard", "2", "--runs", "8"], "expected K/N"),
        (vec!["--shard", "2/4"], "--shard 2/4 needs --runs R"),
        (
            vec!["--shard", "2/4", "--runs", "8", "--seconds", "5"],
            "cannot be used with",
        ),
        (
            vec!["--merge", "a.json", "--runs", "8"],
            "cannot be used with",
        ),
    ] {
        let mut a = vec!["swarm"];
        a.extend(&args);
        let out = mmic(&a);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {out:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(says), "{args:?}: {err}");
    }
    // With the planted bug and --max-failures 1, each shard stops at its first failing seed: the
    // merge keeps their failures and says how many seeds did not run.
    let d = dir("swarm-shard-stopped");
    let args = [
        "--runs",
        "24",
        "--sim-seconds",
        "20",
        "--plant-bug",
        "double-exec",
        "--max-failures",
        "1",
    ];
    let parts = shards(&d, &args, 2);
    let ran: u64 = parts
        .iter()
        .map(|(_, v)| v["seeds"]["count"].as_u64().unwrap())
        .sum();
    assert!(ran < 24, "{ran}");
    assert!(parts.iter().any(|(_, v)| v["shard"]["complete"] == false));
    let merged = merge(&parts).unwrap();
    assert_eq!(merged["merged"]["complete"], false);
    assert_eq!(merged["merged"]["unrun"], 24 - ran);
    assert_eq!(merged["runs"], ran);
    let seeds: Vec<u64> = merged["failures"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["seed"].as_u64().unwrap())
        .collect();
    assert!(
        !seeds.is_empty() && seeds.windows(2).all(|w| w[0] < w[1]),
        "{seeds:?}"
    );
}

/// Issue 40: the Slurm recipe docs/swarm-and-fleets.md shows is, verbatim, the files CI submits
/// (.ci/slurm runs docs/campaigns/slurm/submit on a single-node cluster): each file's name on
/// the page is followed by a block that is the file.
#[test]
fn the_docs_show_the_slurm_recipe_ci_submits_as_it_is() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let page = std::fs::read_to_string(root.join("docs/swarm-and-fleets.md")).unwrap();
    let ci = std::fs::read_to_string(root.join(".ci/slurm")).unwrap();
    assert!(ci.contains("\"$root/docs/campaigns/slurm/submit\""));
    for f in ["submit", "swarm.sbatch", "merge.sbatch"] {
        let path = format!("docs/campaigns/slurm/{f}");
        let file = std::fs::read_to_string(root.join(&path)).unwrap();
        let named = format!("`{path}`");
        let at = page
            .find(&named)
            .unwrap_or_else(|| panic!("the page does not name {path}"));
        let rest = &page[at..];
        let open = rest.find("```sh\n").expect("a block after the name") + "```sh\n".len();
        let len = rest[open..].find("```\n").expect("the block's end");
        assert_eq!(
            &rest[open..open + len],
            file,
            "the page's {path} is not the file"
        );
    }
    // The submit script and the jobs it submits.
    let submit = std::fs::read_to_string(root.join("docs/campaigns/slurm/submit")).unwrap();
    assert!(submit.contains("\"$here/swarm.sbatch\"") && submit.contains("\"$here/merge.sbatch\""));
}
