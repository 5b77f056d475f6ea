//! Writes a CMU-style walk that garnet makes itself (an ASF skeleton and an AMC clip, see
//! `body::pose::synthetic_clip`), for trying the clip readers and `garnet drape --frames`
//! without motion-capture files.
//!
//! ```sh
//! cargo run --release -p body --example synthetic_walk -- OUT_DIR [FRAMES]
//! ```
//!
//! writes `OUT_DIR/cmu/02/02.asf` and `OUT_DIR/cmu/02/02_01.amc` (120 frames by default).

fn main() {
    let mut args = std::env::args().skip(1);
    let Some(dir) = args.next() else {
        eprintln!("usage: synthetic_walk OUT_DIR [FRAMES]");
        std::process::exit(2);
    };
    let frames = match args.next().map(|f| f.parse::<usize>()) {
        None => 120,
        Some(Ok(f)) if f > 0 => f,
        Some(_) => {
            eprintln!("FRAMES must be a positive whole number");
            std::process::exit(2);
        }
    };
    match body::pose::synthetic_clip::write_cmu_clip(dir.as_ref(), "cmu/02/02_01.amc", frames) {
        Ok(amc) => println!("{}", amc.display()),
        Err(e) => {
            eprintln!("synthetic_walk: error: {e}");
            std::process::exit(1);
        }
    }
}
