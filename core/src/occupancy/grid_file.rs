//! The binary grid file (`.nbvgrid`): [`OccupancyGrid::write_to`] / [`OccupancyGrid::save`]
//! (atomic) and [`OccupancyGrid::read_from`] / [`OccupancyGrid::load`] with typed errors.
//! The layout is documented in the [`crate::occupancy`] module doc.

use std::fs::File;
use std::io::{self, BufReader, Read, Write};
use std::path::Path;

use nalgebra::Point3;
use thiserror::Error;

use super::OccupancyError;
use super::grid_geometry::GridGeometry;
use super::log_odds::OccupancyParams;
use super::occupancy_grid::OccupancyGrid;

/// The first 8 bytes of a grid file.
pub const GRID_FILE_MAGIC: [u8; 8] = *b"NBVGRID\0";
/// The format version this code writes and reads.
pub const GRID_FILE_VERSION: u32 = 1;
/// Header length in bytes.
const HEADER_LEN: usize = 80;
/// Values read per chunk: memory grows with the data actually present, never with what a
/// header merely claims.
const CHUNK_VALUES: usize = 1 << 16;

/// Why a grid file could not be read or written.
#[derive(Debug, Error)]
pub enum GridFileError {
    /// An I/O error other than a premature end of file.
    #[error("I/O error on grid file: {0}")]
    Io(#[from] io::Error),
    /// The file does not start with [`GRID_FILE_MAGIC`].
    #[error("not a grid file (magic {0:02x?})")]
    BadMagic([u8; 8]),
    /// A version this code does not read.
    #[error("grid file version {0} is not supported (this build reads version 1)")]
    UnsupportedVersion(u32),
    /// The file ends before the header or the values are complete.
    #[error("grid file truncated: {what} needs {expected} bytes, found {found}")]
    Truncated {
        /// The part being read: "header" or "values".
        what: &'static str,
        /// Bytes needed.
        expected: u64,
        /// Bytes present.
        found: u64,
    },
    /// Bytes follow the last value.
    #[error("grid file has trailing data after {expected} bytes")]
    TrailingData {
        /// The size the header implies.
        expected: u64,
    },
    /// A reserved header field is not zero.
    #[error("grid file reserved field is {0}, expected 0")]
    Reserved(u32),
    /// The header describes an invalid grid or parameters, or a value is not finite.
    #[error("invalid grid in file: {0}")]
    Invalid(#[from] OccupancyError),
}

impl OccupancyGrid {
    /// Writes the grid in the binary format of the [`crate::occupancy`] module doc.
    ///
    /// ```
    /// use nbv_core::occupancy::{GridGeometry, OccupancyGrid, OccupancyParams};
    /// use nalgebra::Point3;
    /// let g = GridGeometry::from_dims(Point3::origin(), 0.02, [4, 3, 2]).unwrap();
    /// let grid = OccupancyGrid::new(g, OccupancyParams::default()).unwrap();
    /// let mut bytes = Vec::new();
    /// grid.write_to(&mut bytes).unwrap();
    /// assert_eq!(bytes.len(), 80 + 4 * 24);
    /// assert_eq!(OccupancyGrid::read_from(&bytes[..]).unwrap(), grid);
    /// ```
    pub fn write_to(&self, mut w: impl Write) -> io::Result<()> {
        let g = self.geometry();
        let p = self.params();
        let dims = g.dims();
        let min = g.min();
        let mut header = Vec::with_capacity(HEADER_LEN);
        header.extend_from_slice(&GRID_FILE_MAGIC);
        header.extend_from_slice(&GRID_FILE_VERSION.to_le_bytes());
        for d in dims {
            // MAX_VOXELS < 2^32 bounds every axis.
            header.extend_from_slice(&(d as u32).to_le_bytes());
        }
        for v in [min.x, min.y, min.z, g.resolution(), p.hit_probability] {
            header.extend_from_slice(&v.to_le_bytes());
        }
        for v in [p.clamp_min, p.clamp_max, p.occupied_epsilon] {
            header.extend_from_slice(&v.to_le_bytes());
        }
        header.extend_from_slice(&0u32.to_le_bytes());
        debug_assert_eq!(header.len(), HEADER_LEN);
        w.write_all(&header)?;
        let mut buf = Vec::with_capacity(4 * CHUNK_VALUES);
        for chunk in self.log_odds().chunks(CHUNK_VALUES) {
            buf.clear();
            for v in chunk {
                buf.extend_from_slice(&v.to_le_bytes());
            }
            w.write_all(&buf)?;
        }
        w.flush()
    }

    /// Writes the grid to `path` atomically: a temporary file in the same directory,
    /// flushed and synced, then renamed over `path`.
    pub fn save(&self, path: impl AsRef<Path>) -> Result<(), GridFileError> {
        crate::atomic_file::write_atomically(path.as_ref(), |w| {
            self.write_to(w).map_err(GridFileError::from)
        })
    }

    /// Reads a grid written by [`OccupancyGrid::write_to`]. The whole input must be one
    /// grid: trailing bytes are an error.
    pub fn read_from(mut r: impl Read) -> Result<Self, GridFileError> {
        let mut header = [0u8; HEADER_LEN];
        let got = read_full(&mut r, &mut header)?;
        if got >= 8 && header[..8] != GRID_FILE_MAGIC {
            let mut magic = [0u8; 8];
            magic.copy_from_slice(&header[..8]);
            return Err(GridFileError::BadMagic(magic));
        }
        if got < HEADER_LEN {
            return Err(GridFileError::Truncated {
                what: "header",
                expected: HEADER_LEN as u64,
                found: got as u64,
            });
        }
        let u32_at =
            |o: usize| u32::from_le_bytes([header[o], header[o + 1], header[o + 2], header[o + 3]]);
        let f32_at = |o: usize| f32::from_bits(u32_at(o));
        let f64_at = |o: usize| {
            let mut b = [0u8; 8];
            b.copy_from_slice(&header[o..o + 8]);
            f64::from_le_bytes(b)
        };
        let version = u32_at(8);
        if version != GRID_FILE_VERSION {
            return Err(GridFileError::UnsupportedVersion(version));
        }
        let reserved = u32_at(76);
        if reserved != 0 {
            return Err(GridFileError::Reserved(reserved));
        }
        let dims = [u32_at(12), u32_at(16), u32_at(20)].map(|d| d as usize);
        let geometry = GridGeometry::from_dims(
            Point3::new(f64_at(24), f64_at(32), f64_at(40)),
            f64_at(48),
            dims,
        )?;
        let params = OccupancyParams {
            hit_probability: f64_at(56),
            clamp_min: f32_at(64),
            clamp_max: f32_at(68),
            occupied_epsilon: f32_at(72),
        };
        params.validate()?;
        let n = geometry.len();
        let expected_bytes = (HEADER_LEN + 4 * n) as u64;
        let mut values: Vec<f32> = Vec::with_capacity(n.min(CHUNK_VALUES));
        let mut buf = vec![0u8; 4 * CHUNK_VALUES];
        while values.len() < n {
            let want = (n - values.len()).min(CHUNK_VALUES);
            let got = read_full(&mut r, &mut buf[..4 * want])?;
            values.extend(
                buf[..got - got % 4]
                    .chunks_exact(4)
                    .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]])),
            );
            if got < 4 * want {
                return Err(GridFileError::Truncated {
                    what: "values",
                    expected: expected_bytes,
                    found: (HEADER_LEN + 4 * values.len() + got % 4) as u64,
                });
            }
        }
        let mut extra = [0u8; 1];
        if read_full(&mut r, &mut extra)? != 0 {
            return Err(GridFileError::TrailingData {
                expected: expected_bytes,
            });
        }
        Ok(OccupancyGrid::from_log_odds(geometry, params, values)?)
    }

    /// Reads a grid file from `path`.
    pub fn load(path: impl AsRef<Path>) -> Result<Self, GridFileError> {
        Self::read_from(BufReader::new(File::open(path)?))
    }
}

/// Reads until `buf` is full or the input ends; returns the bytes read.
fn read_full(r: &mut impl Read, buf: &mut [u8]) -> io::Result<usize> {
    let mut filled = 0;
    while filled < buf.len() {
        match r.read(&mut buf[filled..]) {
            Ok(0) => break,
            Ok(k) => filled += k,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(filled)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::fs;

    fn sample() -> OccupancyGrid {
        let g = GridGeometry::from_dims(Point3::new(0.3, -0.7, 0.23), 0.02, [5, 4, 3]).unwrap();
        let values = (0..60).map(|i| (i as f32 - 30.0) * 0.05).collect();
        let params = OccupancyParams {
            occupied_epsilon: 0.2,
            ..OccupancyParams::default()
        };
        OccupancyGrid::from_log_odds(g, params, values).unwrap()
    }

    fn bytes(grid: &OccupancyGrid) -> Vec<u8> {
        let mut v = Vec::new();
        grid.write_to(&mut v).unwrap();
        v
    }

    #[test]
    fn round_trip_through_a_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("map.nbvgrid");
        let grid = sample();
        grid.save(&path).unwrap();
        let back = OccupancyGrid::load(&path).unwrap();
        assert_eq!(back, grid);
        assert_eq!(fs::metadata(&path).unwrap().len(), 80 + 4 * 60);
        // Overwrite atomically; no temporary left behind.
        grid.save(&path).unwrap();
        let names: Vec<_> = fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names.len(), 1);
    }

    #[test]
    fn header_layout() {
        let b = bytes(&sample());
        assert_eq!(&b[..8], b"NBVGRID\0");
        assert_eq!(u32::from_le_bytes(b[8..12].try_into().unwrap()), 1);
        assert_eq!(u32::from_le_bytes(b[12..16].try_into().unwrap()), 5);
        assert_eq!(f64::from_le_bytes(b[48..56].try_into().unwrap()), 0.02);
        assert_eq!(f32::from_le_bytes(b[80..84].try_into().unwrap()), -1.5);
    }

    #[test]
    fn typed_errors() {
        let good = bytes(&sample());
        let read = |b: &[u8]| OccupancyGrid::read_from(b);
        let mut b = good.clone();
        b[0] = b'X';
        assert!(matches!(read(&b), Err(GridFileError::BadMagic(_))));
        let mut b = good.clone();
        b[8] = 2;
        assert!(matches!(
            read(&b),
            Err(GridFileError::UnsupportedVersion(2))
        ));
        assert!(matches!(
            read(&good[..50]),
            Err(GridFileError::Truncated {
                what: "header",
                expected: 80,
                found: 50
            })
        ));
        assert!(matches!(
            read(&good[..3]),
            Err(GridFileError::Truncated { .. })
        ));
        assert!(matches!(read(&[]), Err(GridFileError::Truncated { .. })));
        assert!(matches!(
            read(&good[..good.len() - 2]),
            Err(GridFileError::Truncated {
                what: "values",
                expected: 320,
                found: 318
            })
        ));
        let mut b = good.clone();
        b.push(0);
        assert!(matches!(
            read(&b),
            Err(GridFileError::TrailingData { expected: 320 })
        ));
        // A header claiming the largest grid, with no data: fails without allocating it.
        let mut b = good[..80].to_vec();
        b[12..16].copy_from_slice(&(1u32 << 10).to_le_bytes());
        b[16..20].copy_from_slice(&(1u32 << 10).to_le_bytes());
        b[20..24].copy_from_slice(&(1u32 << 8).to_le_bytes());
        assert!(matches!(
            read(&b),
            Err(GridFileError::Truncated { what: "values", .. })
        ));
        // Too many voxels, zero dims, bad resolution, bad parameters.
        let mut b = good.clone();
        b[12..16].copy_from_slice(&u32::MAX.to_le_bytes());
        b[16..20].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(matches!(
            read(&b),
            Err(GridFileError::Invalid(OccupancyError::TooManyVoxels { .. }))
        ));
        let mut b = good.clone();
        b[20..24].copy_from_slice(&0u32.to_le_bytes());
        assert!(matches!(read(&b), Err(GridFileError::Invalid(_))));
        let mut b = good.clone();
        b[48..56].copy_from_slice(&(-1.0f64).to_le_bytes());
        assert!(matches!(read(&b), Err(GridFileError::Invalid(_))));
        let mut b = good.clone();
        b[56..64].copy_from_slice(&(1.5f64).to_le_bytes());
        assert!(matches!(read(&b), Err(GridFileError::Invalid(_))));
        let mut b = good.clone();
        b[76] = 1;
        assert!(matches!(read(&b), Err(GridFileError::Reserved(1))));
        let mut b = good.clone();
        b[84..88].copy_from_slice(&f32::NAN.to_le_bytes());
        assert!(matches!(
            read(&b),
            Err(GridFileError::Invalid(OccupancyError::NonFiniteValue {
                index: 1
            }))
        ));
        // Missing file.
        assert!(matches!(
            OccupancyGrid::load("/nonexistent/x.nbvgrid"),
            Err(GridFileError::Io(_))
        ));
    }
}
