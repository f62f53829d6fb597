//! Numeric types of packed point fields (ROS 2 `PointField` and Foxglove
//! `PackedElementField` number them differently), read little-endian.

/// A numeric field type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scalar {
    /// Signed 8-bit integer.
    I8,
    /// Unsigned 8-bit integer.
    U8,
    /// Signed 16-bit integer.
    I16,
    /// Unsigned 16-bit integer.
    U16,
    /// Signed 32-bit integer.
    I32,
    /// Unsigned 32-bit integer.
    U32,
    /// 32-bit float.
    F32,
    /// 64-bit float.
    F64,
}

impl Scalar {
    /// A ROS 2 `sensor_msgs/msg/PointField` datatype (INT8 = 1 … FLOAT64 = 8).
    pub fn from_ros(datatype: u8) -> Option<Scalar> {
        use Scalar::*;
        [I8, U8, I16, U16, I32, U32, F32, F64]
            .get(usize::from(datatype).checked_sub(1)?)
            .copied()
    }

    /// A Foxglove `PackedElementField.NumericType` (UINT8 = 1 … FLOAT64 = 8).
    pub fn from_foxglove(numeric_type: i32) -> Option<Scalar> {
        use Scalar::*;
        let k = usize::try_from(numeric_type).ok()?.checked_sub(1)?;
        [U8, I8, U16, I16, U32, I32, F32, F64].get(k).copied()
    }

    /// Bytes per value.
    pub fn size(self) -> u32 {
        match self {
            Self::I8 | Self::U8 => 1,
            Self::I16 | Self::U16 => 2,
            Self::I32 | Self::U32 | Self::F32 => 4,
            Self::F64 => 8,
        }
    }

    /// True for the integer types.
    pub fn is_integer(self) -> bool {
        !matches!(self, Self::F32 | Self::F64)
    }

    /// The little-endian value at the start of `bytes`, widened to `f64`
    /// (exact for every type); `None` if `bytes` is too short.
    pub fn read_le(self, bytes: &[u8]) -> Option<f64> {
        fn take<const N: usize>(b: &[u8]) -> Option<[u8; N]> {
            b.get(..N)?.try_into().ok()
        }
        Some(match self {
            Self::I8 => f64::from(i8::from_le_bytes(take(bytes)?)),
            Self::U8 => f64::from(u8::from_le_bytes(take(bytes)?)),
            Self::I16 => f64::from(i16::from_le_bytes(take(bytes)?)),
            Self::U16 => f64::from(u16::from_le_bytes(take(bytes)?)),
            Self::I32 => f64::from(i32::from_le_bytes(take(bytes)?)),
            Self::U32 => f64::from(u32::from_le_bytes(take(bytes)?)),
            Self::F32 => f64::from(f32::from_le_bytes(take(bytes)?)),
            Self::F64 => f64::from_le_bytes(take(bytes)?),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ros_and_foxglove_codes_differ_and_are_bounded() {
        assert_eq!(Scalar::from_ros(1), Some(Scalar::I8));
        assert_eq!(Scalar::from_foxglove(1), Some(Scalar::U8));
        assert_eq!(Scalar::from_ros(6), Some(Scalar::U32));
        assert_eq!(Scalar::from_foxglove(6), Some(Scalar::I32));
        assert_eq!(Scalar::from_ros(8), Some(Scalar::F64));
        for bad in [0, 9, 255] {
            assert_eq!(Scalar::from_ros(bad), None);
        }
        assert_eq!(Scalar::from_foxglove(-1), None);
        assert_eq!(Scalar::from_foxglove(9), None);
    }

    #[test]
    fn values_are_read_little_endian_and_short_input_is_none() {
        assert_eq!(Scalar::I16.read_le(&[0xfe, 0xff]), Some(-2.0));
        assert_eq!(Scalar::U32.read_le(&7u32.to_le_bytes()), Some(7.0));
        assert_eq!(Scalar::F32.read_le(&1.5f32.to_le_bytes()), Some(1.5));
        assert_eq!(Scalar::F64.read_le(&[0; 7]), None);
    }
}
