//! The target model as a `foxglove.SceneUpdate`.
//!
//! The mesh is sent once, as two entities locked to the target frames:
//! `target` (the estimate, grey) and `target_truth` (the truth, green,
//! translucent). The pose transforms (`sensor -> target`,
//! `sensor -> target_truth`) then place it at every estimate, so the mesh
//! is never repeated per frame.

use crate::stamp::timestamp;
use crate::topics::{TARGET_FRAME, TARGET_TRUTH_FRAME};
use foxglove::messages::{
    Color, Point3, Pose, Quaternion, SceneEntity, SceneUpdate, TriangleListPrimitive, Vector3,
};

/// A triangle mesh in the target body frame (m).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TargetMesh {
    /// The target's name (e.g. `"deos"`).
    pub name: String,
    /// Vertices in the target body frame (m).
    pub vertices: Vec<[f64; 3]>,
    /// Triangles as indices into `vertices`.
    pub triangles: Vec<[u32; 3]>,
}

impl TargetMesh {
    /// The mesh of `target`, in its body frame (the one conversion from a
    /// target package).
    pub fn of(target: &spacepose_model::Target) -> Self {
        let mesh = target.mesh();
        TargetMesh {
            name: target.name().to_string(),
            vertices: mesh.vertices().iter().map(|v| [v.x, v.y, v.z]).collect(),
            triangles: mesh.triangles().to_vec(),
        }
    }
}

/// The scene holding the target at the estimated and at the true pose,
/// stamped at sensor time `t_s`.
pub fn target_scene(mesh: &TargetMesh, t_s: f64) -> SceneUpdate {
    let estimate = Color {
        r: 0.75,
        g: 0.75,
        b: 0.8,
        a: 0.9,
    };
    let truth = Color {
        r: 0.2,
        g: 0.9,
        b: 0.3,
        a: 0.35,
    };
    SceneUpdate {
        deletions: Vec::new(),
        entities: vec![
            entity(mesh, TARGET_FRAME, estimate, t_s),
            entity(mesh, TARGET_TRUTH_FRAME, truth, t_s),
        ],
    }
}

fn entity(mesh: &TargetMesh, frame: &str, color: Color, t_s: f64) -> SceneEntity {
    let identity = Pose {
        position: Some(Vector3::default()),
        orientation: Some(Quaternion {
            x: 0.0,
            y: 0.0,
            z: 0.0,
            w: 1.0,
        }),
    };
    SceneEntity {
        timestamp: Some(timestamp(t_s)),
        frame_id: frame.to_string(),
        id: format!("{}@{frame}", mesh.name),
        // No lifetime: shown until replaced.
        lifetime: None,
        frame_locked: true,
        triangles: vec![TriangleListPrimitive {
            pose: Some(identity),
            points: mesh
                .vertices
                .iter()
                .map(|v| Point3 {
                    x: v[0],
                    y: v[1],
                    z: v[2],
                })
                .collect(),
            color: Some(color),
            colors: Vec::new(),
            indices: mesh.triangles.iter().flatten().copied().collect(),
        }],
        ..SceneEntity::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use foxglove::{Decode, Encode};

    #[test]
    fn the_mesh_is_placed_in_both_target_frames() {
        let mesh = TargetMesh {
            name: "tetra".into(),
            vertices: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            triangles: vec![[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]],
        };
        let scene = target_scene(&mesh, 4.0);
        let mut buf = Vec::new();
        scene.encode(&mut buf).unwrap();
        let back = SceneUpdate::decode(buf.as_slice()).unwrap();
        assert_eq!(back, scene);
        let frames: Vec<&str> = back.entities.iter().map(|e| e.frame_id.as_str()).collect();
        assert_eq!(frames, ["target", "target_truth"]);
        for e in &back.entities {
            assert!(e.frame_locked);
            let t = &e.triangles[0];
            assert_eq!(t.points.len(), 4);
            assert_eq!(t.indices.len(), 12);
            assert_eq!(&t.indices[9..], &[1, 2, 3]);
        }
    }
}
