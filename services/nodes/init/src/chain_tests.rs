use super::*;
use crate::method::MethodOutput;
use nalgebra::Vector3;
use spacepose_geometry::{Pose, so3};
use spacepose_messages::Name;

/// A fake method: fixed verdict and f_CONV, counts its calls.
struct Fake {
    method: AcquisitionMethod,
    f_conv_m2: f64,
    f_max_m2: f64,
    calls: std::sync::Arc<std::sync::atomic::AtomicUsize>,
}

impl PoseAcquirer for Fake {
    fn method(&self) -> AcquisitionMethod {
        self.method
    }
    fn acquire(&self, cloud: &[Point]) -> Result<MethodOutput, InitError> {
        self.calls
            .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        assert!(cloud.iter().all(Point::is_finite));
        Ok(MethodOutput {
            t_sensor_target: pose(),
            f_conv_m2: self.f_conv_m2,
            // A careless method that accepts a NaN cost.
            accepted: self.f_conv_m2.is_nan() || self.f_conv_m2 <= self.f_max_m2,
            detail: String::new(),
        })
    }
}

fn pose() -> Pose {
    Pose::new(
        so3::exp(&Vector3::new(0.2, -0.4, 1.0)),
        Vector3::new(0.1, 0.2, 15.0),
    )
}

type Calls = std::sync::Arc<std::sync::atomic::AtomicUsize>;

fn fake(method: AcquisitionMethod, f_conv_m2: f64) -> (Box<dyn PoseAcquirer>, Calls) {
    let calls = Calls::default();
    let m = Fake {
        method,
        f_conv_m2,
        f_max_m2: 1e-3,
        calls: calls.clone(),
    };
    (Box::new(m), calls)
}

fn cloud(n: usize) -> Vec<Point> {
    (0..n)
        .map(|i| Point::new(i as f32 * 0.01, 0.0, 15.0, 1.0, 0.0))
        .collect()
}

fn calls(c: &Calls) -> usize {
    c.load(std::sync::atomic::Ordering::Relaxed)
}

#[test]
fn the_first_accepted_method_wins_and_later_ones_are_not_tried() {
    let (cnn, cnn_calls) = fake(AcquisitionMethod::Cnn, 5e-3);
    let (tm, tm_calls) = fake(AcquisitionMethod::TemplateMatching, 4e-4);
    let (spare, spare_calls) = fake(AcquisitionMethod::TemplateMatching, 1e-4);
    let chain = MethodChain::new(vec![cnn, tm, spare], 20).unwrap();
    let a = chain.acquire(&cloud(100));
    assert_eq!(a.attempts.len(), 2);
    assert_eq!(
        (calls(&cnn_calls), calls(&tm_calls), calls(&spare_calls)),
        (1, 1, 0)
    );
    let msg = a.to_wire(7, 8.5, Name::new("init").unwrap());
    assert_eq!(msg.success, 1);
    assert_eq!(msg.method, AcquisitionMethod::TemplateMatching as u8);
    assert_eq!((msg.sequence, msg.t_s, msg.f_conv_m2), (7, 8.5, 4e-4));
    assert!(msg.pose().unwrap().error_to(&pose()).0 < 1e-9);
    assert!(a.summary().contains("cnn rejected"), "{}", a.summary());
}

#[test]
fn when_every_method_rejects_the_result_is_a_failure_with_the_best_fconv() {
    let (cnn, _) = fake(AcquisitionMethod::Cnn, 5e-3);
    let (tm, _) = fake(AcquisitionMethod::TemplateMatching, 2e-3);
    let chain = MethodChain::new(vec![cnn, tm], 20).unwrap();
    let msg = chain
        .acquire(&cloud(100))
        .to_wire(3, 4.0, Name::new("init").unwrap());
    assert_eq!(msg.success, 0);
    assert_eq!(msg.method, AcquisitionMethod::TemplateMatching as u8);
    assert_eq!(msg.f_conv_m2, 2e-3);
    // The pose of a failure is never handed out.
    assert_eq!(msg.q_sensor_target, [1.0, 0.0, 0.0, 0.0]);
    assert_eq!(msg.p_sensor_target, [0.0; 3]);
}

#[test]
fn sparse_and_non_finite_clouds_fail_without_running_a_method() {
    let (tm, tm_calls) = fake(AcquisitionMethod::TemplateMatching, 0.0);
    let chain = MethodChain::new(vec![tm], 20).unwrap();
    let mut nan = cloud(500);
    for p in &mut nan {
        p.x = f32::NAN;
    }
    for bad in [vec![], cloud(19), nan] {
        let a = chain.acquire(&bad);
        assert!(a.accepted().is_none());
        let msg = a.to_wire(1, 1.0, Name::new("init").unwrap());
        assert_eq!(msg.success, 0);
        assert!(msg.f_conv_m2.is_nan());
        assert!(a.summary().contains("too few points"), "{}", a.summary());
        assert!(a.summary().contains("no method tried"), "{}", a.summary());
        assert!(a.attempts.is_empty());
        assert_eq!(msg.method, AcquisitionMethod::TemplateMatching as u8);
    }
    assert_eq!(calls(&tm_calls), 0);
    // 20 finite points among NaNs are enough to try.
    let mut mixed = cloud(20);
    mixed.push(Point::new(f32::NAN, 0.0, 0.0, 0.0, 0.0));
    assert!(chain.acquire(&mixed).accepted().is_some());
    assert_eq!(calls(&tm_calls), 1);
}

#[test]
fn a_non_finite_output_is_never_accepted() {
    let (tm, _) = fake(AcquisitionMethod::TemplateMatching, f64::NAN);
    let chain = MethodChain::new(vec![tm], 20).unwrap();
    let a = chain.acquire(&cloud(50));
    assert!(a.accepted().is_none());
    assert_eq!(a.to_wire(1, 1.0, Name::new("init").unwrap()).success, 0);
    assert!(MethodChain::new(vec![], 20).is_err());
}
