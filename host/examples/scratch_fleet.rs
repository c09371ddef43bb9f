fn main() {
    let opts = mmic_host::swarm::scenario::Options::default();
    let n: u64 = std::env::args().nth(1).map(|s| s.parse().unwrap()).unwrap_or(50);
    let r = mmic_host::swarm::swarm(1, std::time::Duration::from_secs(600), Some(n), 100, &opts, &mut |l| eprintln!("{l}"));
    print!("{}", r.text(&opts));
}
