//! Writes a synthetic drive (see `benches/common/bag.rs`) for measuring
//! `gaze-lidar replay`: `cargo run --release --example make_bag -- OUT.mcap SECONDS`
//! (≈ 51 MB per second of drive: 43 s ≈ 2.1 GiB).

#[path = "../benches/common/bag.rs"]
mod bag;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (Some(path), Some(secs)) = (args.get(1), args.get(2).and_then(|s| s.parse().ok())) else {
        eprintln!("usage: make_bag OUT.mcap SECONDS");
        std::process::exit(2);
    };
    let f = std::fs::File::create(path).unwrap_or_else(|e| {
        eprintln!("{path}: {e}");
        std::process::exit(2)
    });
    if let Err(e) = bag::write_bag(std::io::BufWriter::new(f), secs) {
        eprintln!("{path}: {e}");
        std::process::exit(1);
    }
}
