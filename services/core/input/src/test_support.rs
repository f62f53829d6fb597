//! Hand-built messages for the tests: PointCloud2 CDR and Foxglove clouds.

use foxglove::Encode;
use foxglove::messages::{PackedElementField, PointCloud, Timestamp};

/// Writes plain little-endian CDR (alignment relative to after the header).
pub(crate) struct CdrWriter(pub Vec<u8>);

impl CdrWriter {
    pub(crate) fn new() -> Self {
        CdrWriter(vec![0, 1, 0, 0])
    }
    fn align(&mut self, n: usize) {
        while !(self.0.len() - 4).is_multiple_of(n) {
            self.0.push(0);
        }
    }
    pub(crate) fn u8(&mut self, v: u8) -> &mut Self {
        self.0.push(v);
        self
    }
    pub(crate) fn u32(&mut self, v: u32) -> &mut Self {
        self.align(4);
        self.0.extend_from_slice(&v.to_le_bytes());
        self
    }
    pub(crate) fn string(&mut self, s: &str) -> &mut Self {
        self.u32(s.len() as u32 + 1);
        self.0.extend_from_slice(s.as_bytes());
        self.0.push(0);
        self
    }
    pub(crate) fn bytes(&mut self, b: &[u8]) -> &mut Self {
        self.u32(b.len() as u32);
        self.0.extend_from_slice(b);
        self
    }
}

/// A PointCloud2 description to serialise.
#[derive(Clone)]
pub(crate) struct Cloud2 {
    pub stamp: (u32, u32),
    pub fields: Vec<(&'static str, u32, u8, u32)>,
    pub height: u32,
    pub width: u32,
    pub point_step: u32,
    pub row_step: u32,
    pub data: Vec<u8>,
    pub is_dense: bool,
    pub is_bigendian: bool,
}

impl Cloud2 {
    /// `points` as x y z intensity FLOAT32 (0..16) plus, if given, a time
    /// field of ROS datatype `time.1` at offset 16.
    pub(crate) fn xyzi(
        points: &[[f32; 4]],
        time: Option<(&'static str, u8, &[Vec<u8>])>,
    ) -> Cloud2 {
        let mut fields = vec![
            ("x", 0, 7, 1),
            ("y", 4, 7, 1),
            ("z", 8, 7, 1),
            ("intensity", 12, 7, 1),
        ];
        let time_size = time.map_or(0, |(_, _, v)| v.first().map_or(0, Vec::len));
        if let Some((name, datatype, _)) = time {
            fields.push((name, 16, datatype, 1));
        }
        let point_step = 16 + time_size as u32;
        let mut data = Vec::new();
        for (i, p) in points.iter().enumerate() {
            for v in p {
                data.extend_from_slice(&v.to_le_bytes());
            }
            if let Some((_, _, values)) = time {
                data.extend_from_slice(&values[i]);
            }
        }
        Cloud2 {
            stamp: (100, 500_000_000),
            fields,
            height: 1,
            width: points.len() as u32,
            point_step,
            row_step: point_step * points.len() as u32,
            data,
            is_dense: true,
            is_bigendian: false,
        }
    }

    pub(crate) fn to_cdr(&self) -> Vec<u8> {
        let mut w = CdrWriter::new();
        w.u32(self.stamp.0).u32(self.stamp.1).string("lidar");
        w.u32(self.height)
            .u32(self.width)
            .u32(self.fields.len() as u32);
        for &(name, offset, datatype, count) in &self.fields {
            w.string(name).u32(offset).u8(datatype).u32(count);
        }
        w.u8(self.is_bigendian as u8);
        w.u32(self.point_step).u32(self.row_step).bytes(&self.data);
        w.u8(self.is_dense as u8);
        w.0
    }
}

/// A cloud in the layout spacepose writes: x y z intensity FLOAT32, t FLOAT64.
pub(crate) fn spacepose_cloud(points: &[[f64; 5]]) -> Vec<u8> {
    let field = |name: &str, offset, r#type| PackedElementField {
        name: name.into(),
        offset,
        r#type,
    };
    let mut data = Vec::new();
    for p in points {
        for v in &p[..4] {
            data.extend_from_slice(&(*v as f32).to_le_bytes());
        }
        data.extend_from_slice(&p[4].to_le_bytes());
    }
    let cloud = PointCloud {
        timestamp: Some(Timestamp::new(7, 250_000_000)),
        frame_id: "sensor".into(),
        pose: None,
        point_stride: 24,
        fields: vec![
            field("x", 0, 7),
            field("y", 4, 7),
            field("z", 8, 7),
            field("intensity", 12, 7),
            field("t", 16, 8),
        ],
        data: data.into(),
    };
    let mut bytes = Vec::new();
    cloud.encode(&mut bytes).unwrap();
    bytes
}
