//! Writes a large profile@1 file (the `check` benchmark's workload) to
//! stdout: `cargo run --release --example big_profile -- N [smooth|rough]`.

#[path = "../benches/common/big_profile.rs"]
mod big_profile;

use big_profile::{big_profile, Roughness};

fn main() {
    let mut args = std::env::args().skip(1);
    let n: usize = match args.next().map(|s| s.parse()) {
        Some(Ok(n)) if n >= 400 => n,
        _ => {
            eprintln!("usage: big_profile N [smooth|rough] (N >= 400)");
            std::process::exit(2);
        }
    };
    let roughness = match args.next().as_deref() {
        None | Some("smooth") => Roughness::Smooth,
        Some("rough") => Roughness::Rough,
        Some(other) => {
            eprintln!("roughness: expected smooth or rough, got {other}");
            std::process::exit(2);
        }
    };
    let json = big_profile(n, roughness)
        .to_json()
        .expect("a profile serializes");
    println!("{json}");
}
