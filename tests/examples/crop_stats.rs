//! Diagnostic: for a running deployment, how many points of each cropped
//! cloud (ingest output) lie off the target surface (clutter kept), using the
//! simulator's truth (constant velocities over the scan, as the simulator).
//!
//! usage: cargo run --release -p spacepose-e2e --example crop_stats -- PREFIX FRAMES
#![allow(clippy::unwrap_used)]

use nalgebra::Vector3;
use spacepose_bus::Bus;
use spacepose_geometry::Pose;
use spacepose_messages::{Names, TruthMsg};
use std::collections::BTreeMap;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let names = Names::new(&args[1]).unwrap();
    let frames: usize = args[2].parse().unwrap();
    let target = spacepose_model::Target::resolve("deos", 1.0).unwrap();
    let bus = Bus::open(&names, "crop-stats").unwrap();
    let clouds = bus.cloud_subscriber(&names.cloud()).unwrap();
    let truths = bus.subscriber::<TruthMsg>(&names.truth()).unwrap();
    let mut truth = BTreeMap::new();
    let mut pending = BTreeMap::new();
    let mut done = 0;
    while done < frames {
        while let Some(t) = truths.try_recv().unwrap() {
            truth.insert(t.sequence, t);
        }
        while let Some(c) = clouds.try_recv().unwrap() {
            pending.insert(c.header().sequence, c.points().to_vec());
        }
        let ready: Vec<u64> = pending
            .keys()
            .copied()
            .filter(|k| truth.contains_key(k))
            .collect();
        for k in ready {
            let pts = pending.remove(&k).unwrap();
            let t = truth[&k];
            let pose = t.pose().unwrap();
            let v = Vector3::from(t.v_sensor);
            let w = Vector3::from(t.w_target);
            let mut off = [0usize; 3];
            for p in &pts {
                let dt = p.t - t.t_s;
                let at = Pose::new(
                    pose.rotation * nalgebra::Rotation3::new(w * dt),
                    pose.translation + v * dt,
                );
                let d = target
                    .mesh()
                    .distance_to_surface(&at.inverse().transform(&p.position()));
                off[0] += usize::from(d > 0.05);
                off[1] += usize::from(d > 0.15);
                off[2] += usize::from(d > 0.5);
            }
            println!(
                "frame {k}: {} points, off surface >5cm {} >15cm {} >50cm {}",
                pts.len(),
                off[0],
                off[1],
                off[2]
            );
            done += 1;
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
}
