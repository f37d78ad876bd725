//! `PointCloud2` ⇄ xyz points: [`cloud_from_points`] / [`cloud_from_points_f64`] build an
//! unordered FLOAT32 x,y,z cloud; [`cloud_xyz`] reads x, y, z from any user's cloud
//! (FLOAT32 or FLOAT64 fields at any offsets and in any order, padding, organised clouds),
//! skipping points with a NaN or infinite coordinate.

use nalgebra::Point3;

use crate::error::CloudError;
use crate::messages::{Header, PointCloud2, PointField};

/// An unordered cloud (`height` 1) of `points`: x, y, z FLOAT32 at offsets 0, 4, 8,
/// `point_step` 12, little-endian, `is_dense` true unless some coordinate is NaN/Inf.
///
/// ```
/// use nbv_bag::messages::Header;
/// use nbv_bag::point_cloud::{cloud_from_points, cloud_xyz};
/// let cloud = cloud_from_points(Header::default(), &[[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]);
/// assert_eq!((cloud.width, cloud.point_step, cloud.data.len()), (2, 12, 24));
/// let back = cloud_xyz(&cloud).unwrap();
/// assert_eq!(back[1].y, 5.0);
/// ```
pub fn cloud_from_points(header: Header, points: &[[f32; 3]]) -> PointCloud2 {
    let field = |name: &str, offset| PointField {
        name: name.into(),
        offset,
        datatype: PointField::FLOAT32,
        count: 1,
    };
    let data: Vec<u8> = points
        .iter()
        .flatten()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    let width = u32::try_from(points.len()).unwrap_or(u32::MAX);
    PointCloud2 {
        header,
        height: 1,
        width,
        fields: vec![field("x", 0), field("y", 4), field("z", 8)],
        is_bigendian: false,
        point_step: 12,
        row_step: width.saturating_mul(12),
        data,
        is_dense: points.iter().flatten().all(|v| v.is_finite()),
    }
}

/// [`cloud_from_points`] of f64 points (narrowed to f32 on the wire, as ROS clouds are).
pub fn cloud_from_points_f64(header: Header, points: &[Point3<f64>]) -> PointCloud2 {
    #[allow(clippy::cast_possible_truncation)]
    let narrowed: Vec<[f32; 3]> = points
        .iter()
        .map(|p| [p.x as f32, p.y as f32, p.z as f32])
        .collect();
    cloud_from_points(header, &narrowed)
}

/// Where one coordinate sits in a point's record.
#[derive(Debug, Clone, Copy)]
struct Coord {
    offset: usize,
    f64: bool,
}

fn coord(cloud: &PointCloud2, name: &'static str) -> Result<Coord, CloudError> {
    let f = cloud
        .fields
        .iter()
        .find(|f| f.name == name)
        .ok_or(CloudError::MissingField(name))?;
    let (size, f64) = match f.datatype {
        PointField::FLOAT32 => (4u32, false),
        PointField::FLOAT64 => (8u32, true),
        datatype => {
            return Err(CloudError::Datatype {
                field: name,
                datatype,
            });
        }
    };
    if f.offset
        .checked_add(size)
        .is_none_or(|end| end > cloud.point_step)
    {
        return Err(CloudError::FieldOutOfBounds {
            field: name,
            offset: f.offset,
            size,
            point_step: cloud.point_step,
        });
    }
    Ok(Coord {
        offset: f.offset as usize,
        f64,
    })
}

fn read(record: &[u8], c: Coord) -> f64 {
    if c.f64 {
        let mut b = [0u8; 8];
        b.copy_from_slice(&record[c.offset..c.offset + 8]);
        f64::from_le_bytes(b)
    } else {
        let mut b = [0u8; 4];
        b.copy_from_slice(&record[c.offset..c.offset + 4]);
        f64::from(f32::from_le_bytes(b))
    }
}

/// The finite xyz points of `cloud`, row by row, in the cloud's frame. A field with
/// `count > 1` is read at its first value.
///
/// # Errors
/// [`CloudError`] for a big-endian cloud, a missing x/y/z field, a field that is not
/// FLOAT32/FLOAT64 or that overruns `point_step`, `row_step < width·point_step`, or
/// `data.len() != row_step·height`.
pub fn cloud_xyz(cloud: &PointCloud2) -> Result<Vec<Point3<f64>>, CloudError> {
    if cloud.is_bigendian {
        return Err(CloudError::BigEndian);
    }
    let [x, y, z] = [coord(cloud, "x")?, coord(cloud, "y")?, coord(cloud, "z")?];
    let expected = u64::from(cloud.row_step) * u64::from(cloud.height);
    if cloud.data.len() as u64 != expected {
        return Err(CloudError::DataSize {
            len: cloud.data.len(),
            expected,
        });
    }
    if u64::from(cloud.row_step) < u64::from(cloud.width) * u64::from(cloud.point_step) {
        return Err(CloudError::RowStep {
            row_step: cloud.row_step,
            width: cloud.width,
            point_step: cloud.point_step,
        });
    }
    let (row_step, point_step) = (cloud.row_step as usize, cloud.point_step as usize);
    let mut points = Vec::with_capacity(
        (cloud.width as usize)
            .saturating_mul(cloud.height as usize)
            .min(cloud.data.len()),
    );
    for r in 0..cloud.height as usize {
        let row = &cloud.data[r * row_step..(r + 1) * row_step];
        for c in 0..cloud.width as usize {
            let record = &row[c * point_step..(c + 1) * point_step];
            let p = Point3::new(read(record, x), read(record, y), read(record, z));
            if p.coords.iter().all(|v| v.is_finite()) {
                points.push(p);
            }
        }
    }
    Ok(points)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn field(name: &str, offset: u32, datatype: u8) -> PointField {
        PointField {
            name: name.into(),
            offset,
            datatype,
            count: 1,
        }
    }

    /// A 2×2 organised cloud, fields z, x, y (f32) in a 16-byte record with 4 bytes of
    /// padding at the front, rows padded to 40 bytes; one point has a NaN.
    #[test]
    fn organised_with_padding_and_nan() {
        let pts = [
            [1.0f32, 2.0, 3.0],
            [4.0, f32::NAN, 6.0],
            [7.0, 8.0, 9.0],
            [10.0, 11.0, 12.0],
        ];
        let mut data = Vec::new();
        for row in pts.chunks(2) {
            for p in row {
                data.extend_from_slice(&[0xAA; 4]);
                for v in [p[2], p[0], p[1]] {
                    data.extend_from_slice(&v.to_le_bytes());
                }
            }
            data.extend_from_slice(&[0xBB; 8]);
        }
        let cloud = PointCloud2 {
            height: 2,
            width: 2,
            fields: vec![
                field("z", 4, PointField::FLOAT32),
                field("x", 8, PointField::FLOAT32),
                field("y", 12, PointField::FLOAT32),
            ],
            point_step: 16,
            row_step: 40,
            data,
            ..Default::default()
        };
        let got = cloud_xyz(&cloud).unwrap();
        assert_eq!(
            got,
            vec![
                Point3::new(1.0, 2.0, 3.0),
                Point3::new(7.0, 8.0, 9.0),
                Point3::new(10.0, 11.0, 12.0)
            ]
        );
    }

    #[test]
    fn float64_fields() {
        let mut data = Vec::new();
        for v in [0.1f64, 0.2, 0.3] {
            data.extend_from_slice(&v.to_le_bytes());
        }
        data.extend_from_slice(&[0; 8]);
        let cloud = PointCloud2 {
            height: 1,
            width: 1,
            fields: vec![
                field("x", 0, PointField::FLOAT64),
                field("y", 8, PointField::FLOAT64),
                field("z", 16, PointField::FLOAT64),
            ],
            point_step: 32,
            row_step: 32,
            data,
            ..Default::default()
        };
        assert_eq!(cloud_xyz(&cloud).unwrap(), vec![Point3::new(0.1, 0.2, 0.3)]);
    }

    #[test]
    fn refusals() {
        let good = cloud_from_points(Header::default(), &[[1.0, 2.0, 3.0]]);
        let mut c = good.clone();
        c.is_bigendian = true;
        assert_eq!(cloud_xyz(&c).unwrap_err(), CloudError::BigEndian);
        let mut c = good.clone();
        c.fields.remove(1);
        assert_eq!(cloud_xyz(&c).unwrap_err(), CloudError::MissingField("y"));
        let mut c = good.clone();
        c.data.pop();
        let e = cloud_xyz(&c).unwrap_err();
        assert_eq!(
            e,
            CloudError::DataSize {
                len: 11,
                expected: 12
            }
        );
        assert_eq!(
            e.to_string(),
            "point cloud data is 11 bytes, row_step×height says 12"
        );
        let mut c = good.clone();
        c.fields[2].offset = 10;
        assert!(matches!(
            cloud_xyz(&c),
            Err(CloudError::FieldOutOfBounds { field: "z", .. })
        ));
        let mut c = good.clone();
        c.fields[0].datatype = PointField::INT16;
        assert!(matches!(
            cloud_xyz(&c),
            Err(CloudError::Datatype {
                field: "x",
                datatype: 3
            })
        ));
        let mut c = good;
        c.width = 2;
        assert!(matches!(cloud_xyz(&c), Err(CloudError::RowStep { .. })));
    }

    #[test]
    fn f64_points_round_trip_through_f32() {
        let c = cloud_from_points_f64(Header::default(), &[Point3::new(0.5, -1.25, 2.0)]);
        assert!(c.is_dense);
        assert_eq!(cloud_xyz(&c).unwrap(), vec![Point3::new(0.5, -1.25, 2.0)]);
        let c = cloud_from_points(Header::default(), &[[f32::INFINITY, 0.0, 0.0]]);
        assert!(!c.is_dense);
        assert!(cloud_xyz(&c).unwrap().is_empty());
    }
}
