//! Prints the shape of the house: import circles per crate target,
//! production files over 400 lines, service mains over 40 lines, and what
//! each algorithm crate reaches of the bus (`tests/tests/layout.rs` holds
//! the rules).
//!
//! `cargo run --release -p spacepose-e2e --example layout`

use spacepose_e2e::layout::{CrateModules, Metadata, circles, forbidden_paths, line_count};
use spacepose_e2e::repo_root;

fn main() -> Result<(), String> {
    let root = repo_root();
    let meta = Metadata::load(&root)?;
    let mut total_circles = 0;
    let mut big = Vec::new();
    for id in &meta.members {
        let p = &meta.packages[id];
        for (kind, src) in &p.targets {
            if kind != "lib" && kind != "bin" {
                continue;
            }
            let c = CrateModules::load(src)?;
            for circle in circles(&c) {
                total_circles += 1;
                let names: Vec<_> = circle
                    .iter()
                    .map(|f| f.strip_prefix(&root).unwrap_or(f).display().to_string())
                    .collect();
                println!("circle in {} ({kind}): {}", p.name, names.join(" "));
            }
            for f in c.production_files() {
                let n = line_count(f);
                if n > 400 {
                    big.push((n, f.strip_prefix(&root).unwrap_or(f).display().to_string()));
                }
            }
        }
    }
    big.sort();
    big.dedup();
    for (n, f) in &big {
        println!("{n:5} lines: {f}");
    }
    println!(
        "{total_circles} import circles, {} production files over 400 lines",
        big.len()
    );
    for id in meta.members_under(&root.join("services").join("core")) {
        let bus = |n: &str| {
            n.starts_with("iceoryx2")
                || n.starts_with("zenoh")
                || n == "spacepose-bus"
                || n == "spacepose-messages"
                || n == "spacepose-runtime"
        };
        for path in forbidden_paths(&meta, id, false, bus).iter().take(1) {
            println!("{} reaches {}", meta.packages[id].name, path.join(" -> "));
        }
    }
    Ok(())
}
