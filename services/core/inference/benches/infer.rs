//! Inference latency at batch 1 on one thread, tract and (feature `ort`) ONNX
//! Runtime. The model is `$SPACEPOSE_MODEL` (its shape read from the
//! `model.json` beside it: `image_size`, `classes`) or the test fixture.
//!
//! `cargo bench -p spacepose-inference [--features ort] --bench infer`
//! prints criterion's statistics and a plain median over 201 runs.

use std::path::{Path, PathBuf};
use std::time::Instant;

use criterion::{Criterion, criterion_group, criterion_main};
use spacepose_inference::{Engine, ModelShape, PoseNet};

fn model() -> (PathBuf, ModelShape) {
    let fixtures = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures");
    let (path, meta) = match std::env::var_os("SPACEPOSE_MODEL") {
        Some(p) => {
            let path = PathBuf::from(p);
            let meta = path.with_file_name("model.json");
            (path, meta)
        }
        None => (
            fixtures.join("tiny_posenet.onnx"),
            fixtures.join("expected.json"),
        ),
    };
    let text = std::fs::read_to_string(&meta).unwrap_or_else(|e| panic!("{}: {e}", meta.display()));
    let json: serde_json::Value = serde_json::from_str(&text).expect("model metadata is not JSON");
    let field = |key: &str| {
        json[key]
            .as_u64()
            .and_then(|v| usize::try_from(v).ok())
            .unwrap_or_else(|| panic!("{}: no integer `{key}`", meta.display()))
    };
    let shape = ModelShape {
        image_size: field("image_size"),
        classes: field("classes"),
    };
    (path, shape)
}

/// A disc of depths around the image centre, the rest empty.
fn depth_image(n: usize) -> Vec<f32> {
    let c = (n as f32 - 1.0) / 2.0;
    let r2_max = (n as f32 / 3.0).powi(2);
    (0..n * n)
        .map(|i| {
            let (y, x) = ((i / n) as f32 - c, (i % n) as f32 - c);
            let r2 = x * x + y * y;
            if r2 < r2_max {
                0.4 + 0.2 * r2 / r2_max
            } else {
                0.0
            }
        })
        .collect()
}

fn bench_engine(c: &mut Criterion, engine: Engine) {
    let (path, shape) = model();
    let name = engine.name();
    let mut net = PoseNet::load(&path, engine, shape).unwrap_or_else(|e| panic!("{e}"));
    let depth = depth_image(shape.image_size);
    let mut times_ms: Vec<f64> = (0..201)
        .map(|_| {
            let start = Instant::now();
            std::hint::black_box(net.infer(&depth).expect("inference"));
            start.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    times_ms.sort_by(f64::total_cmp);
    println!(
        "{name}: {} N={} m={}: median {:.4} ms over {} runs (min {:.4})",
        path.display(),
        shape.image_size,
        shape.classes,
        times_ms[times_ms.len() / 2],
        times_ms.len(),
        times_ms[0]
    );
    c.bench_function(&format!("infer/{name}"), |b| {
        b.iter(|| std::hint::black_box(net.infer(&depth).expect("inference")))
    });
}

fn tract(c: &mut Criterion) {
    bench_engine(c, Engine::Tract);
}

#[cfg(feature = "ort")]
fn ort(c: &mut Criterion) {
    match Engine::ort_default() {
        Ok(engine) => bench_engine(c, engine),
        Err(e) => println!("ort skipped: {e}"),
    }
}

#[cfg(not(feature = "ort"))]
fn ort(_c: &mut Criterion) {
    println!("ort skipped: built without `--features ort`");
}

criterion_group!(benches, tract, ort);
criterion_main!(benches);
