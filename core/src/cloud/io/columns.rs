//! The mapping between file fields (PLY properties, PCD fields) and [`PointCloud`]
//! columns: which names feed which column when reading, which names and types are written,
//! and the builder that assembles decoded records into a cloud.

use nalgebra::{Point3, Vector3};

use super::error::{CloudIoError, CloudIoErrorKind, Location};
use super::options::FloatType;
use super::scalar::ScalarType;
use crate::cloud::{CloudError, PointCloud};

/// One coordinate of one cloud column.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Role {
    X,
    Y,
    Z,
    Nx,
    Ny,
    Nz,
    Ox,
    Oy,
    Oz,
    Label,
    View,
    Tx,
    Ty,
    Tz,
}

/// Number of [`Role`]s: the length of a decoded record.
pub(crate) const ROLES: usize = 14;

/// A decoded record: one value per role (unused roles stay 0).
pub(crate) type Record = [f64; ROLES];

impl Role {
    /// Index into a [`Record`].
    pub(crate) fn index(self) -> usize {
        self as usize
    }
}

/// The role of a field name. Accepted names: `x y z`; normals `nx ny nz` (Open3D,
/// MeshLab) or `normal_x normal_y normal_z` (PCL); sensor origins `ox oy oz` or `vp_x vp_y
/// vp_z` (PCL's `PointWithViewpoint`); `label`; `view`; ground truth `tx ty tz`.
pub(crate) fn role_of(name: &str) -> Option<Role> {
    Some(match name {
        "x" => Role::X,
        "y" => Role::Y,
        "z" => Role::Z,
        "nx" | "normal_x" => Role::Nx,
        "ny" | "normal_y" => Role::Ny,
        "nz" | "normal_z" => Role::Nz,
        "ox" | "vp_x" => Role::Ox,
        "oy" | "vp_y" => Role::Oy,
        "oz" | "vp_z" => Role::Oz,
        "label" => Role::Label,
        "view" => Role::View,
        "tx" => Role::Tx,
        "ty" => Role::Ty,
        "tz" => Role::Tz,
        _ => return None,
    })
}

/// Which columns a file provides, and the role of each of its fields.
#[derive(Debug, Clone)]
pub(crate) struct FieldMap {
    /// Role of each field in file order (`None`: skipped).
    pub(crate) roles: Vec<Option<Role>>,
    /// Names of the skipped fields.
    pub(crate) ignored: Vec<String>,
    present: [bool; ROLES],
}

impl FieldMap {
    /// Maps field names to roles. Fails if `x y z` are missing, if a role is given twice
    /// (`nx` and `normal_x`), or if a 3-vector column is incomplete (`nx ny` without `nz`).
    pub(crate) fn new<'a>(
        names: impl IntoIterator<Item = &'a str>,
    ) -> Result<Self, CloudIoErrorKind> {
        let mut roles = Vec::new();
        let mut ignored = Vec::new();
        let mut first: [Option<&str>; ROLES] = [None; ROLES];
        for name in names {
            let role = role_of(name);
            match role {
                Some(r) => {
                    if let Some(prev) = first[r.index()] {
                        return Err(CloudIoErrorKind::Header(format!(
                            "fields `{prev}` and `{name}` give the same value"
                        )));
                    }
                    first[r.index()] = Some(name);
                }
                None => ignored.push(name.to_owned()),
            }
            roles.push(role);
        }
        let present = first.map(|n| n.is_some());
        for (group, names) in [
            ([Role::X, Role::Y, Role::Z], "x, y and z"),
            (
                [Role::Nx, Role::Ny, Role::Nz],
                "nx, ny and nz (or normal_x, normal_y and normal_z)",
            ),
            (
                [Role::Ox, Role::Oy, Role::Oz],
                "ox, oy and oz (or vp_x, vp_y and vp_z)",
            ),
            ([Role::Tx, Role::Ty, Role::Tz], "tx, ty and tz"),
        ] {
            let n = group.iter().filter(|r| present[r.index()]).count();
            let required = group[0] == Role::X;
            if (n > 0 || required) && n < 3 {
                return Err(CloudIoErrorKind::Header(format!(
                    "the point fields need all of {names}; some are missing"
                )));
            }
        }
        Ok(Self {
            roles,
            ignored,
            present,
        })
    }

    fn has(&self, role: Role) -> bool {
        self.present[role.index()]
    }
}

/// Assembles decoded records into a [`PointCloud`] with the columns of a [`FieldMap`].
pub(crate) struct CloudBuilder {
    cloud: PointCloud,
}

impl CloudBuilder {
    /// A builder for the columns of `map`, with room for `capacity` points (the caller
    /// bounds it by the data actually present).
    pub(crate) fn new(map: &FieldMap, capacity: usize) -> Self {
        fn col<T>(on: bool, capacity: usize) -> Option<Vec<T>> {
            on.then(|| Vec::with_capacity(capacity))
        }
        Self {
            cloud: PointCloud {
                points: Vec::with_capacity(capacity),
                origins: col(map.has(Role::Ox), capacity),
                normals: col(map.has(Role::Nx), capacity),
                labels: col(map.has(Role::Label), capacity),
                views: col(map.has(Role::View), capacity),
                truth: col(map.has(Role::Tx), capacity),
            },
        }
    }

    /// Appends one record.
    pub(crate) fn push(&mut self, r: &Record) -> Result<(), CloudIoErrorKind> {
        let p = |a: Role, b: Role, c: Role| Point3::new(r[a.index()], r[b.index()], r[c.index()]);
        let c = &mut self.cloud;
        if let Some(l) = &mut c.labels {
            l.push(index_value("label", r[Role::Label.index()])?);
        }
        if let Some(v) = &mut c.views {
            v.push(index_value("view", r[Role::View.index()])?);
        }
        c.points.push(p(Role::X, Role::Y, Role::Z));
        if let Some(o) = &mut c.origins {
            o.push(p(Role::Ox, Role::Oy, Role::Oz));
        }
        if let Some(n) = &mut c.normals {
            n.push(Vector3::new(
                r[Role::Nx.index()],
                r[Role::Ny.index()],
                r[Role::Nz.index()],
            ));
        }
        if let Some(t) = &mut c.truth {
            t.push(p(Role::Tx, Role::Ty, Role::Tz));
        }
        Ok(())
    }

    /// The cloud.
    pub(crate) fn finish(self) -> PointCloud {
        self.cloud
    }
}

/// A label or view index: an integer in `0..=u32::MAX` (whatever the stored type).
fn index_value(column: &'static str, v: f64) -> Result<u32, CloudIoErrorKind> {
    if v.fract() == 0.0 && (0.0..=f64::from(u32::MAX)).contains(&v) {
        Ok(v as u32)
    } else {
        Err(CloudIoErrorKind::BadIndex { column, value: v })
    }
}

/// The names a format writes for the vector columns.
pub(crate) struct ColumnNames {
    pub(crate) normals: [&'static str; 3],
    pub(crate) origins: [&'static str; 3],
}

/// A field to write.
#[derive(Debug, Clone, Copy)]
pub(crate) struct OutField {
    pub(crate) name: &'static str,
    pub(crate) role: Role,
    pub(crate) ty: ScalarType,
}

/// The fields written for `cloud`, in order: x y z, normals, origins, label, view, truth.
pub(crate) fn out_fields(
    cloud: &PointCloud,
    float: FloatType,
    names: &ColumnNames,
) -> Vec<OutField> {
    let f = match float {
        FloatType::F32 => ScalarType::F32,
        FloatType::F64 => ScalarType::F64,
    };
    let mut out = Vec::new();
    let push3 = |out: &mut Vec<OutField>, n: [&'static str; 3], r: [Role; 3]| {
        for (name, role) in n.into_iter().zip(r) {
            out.push(OutField { name, role, ty: f });
        }
    };
    push3(&mut out, ["x", "y", "z"], [Role::X, Role::Y, Role::Z]);
    if cloud.normals.is_some() {
        push3(&mut out, names.normals, [Role::Nx, Role::Ny, Role::Nz]);
    }
    if cloud.origins.is_some() {
        push3(&mut out, names.origins, [Role::Ox, Role::Oy, Role::Oz]);
    }
    if cloud.labels.is_some() {
        out.push(OutField {
            name: "label",
            role: Role::Label,
            ty: ScalarType::U32,
        });
    }
    if cloud.views.is_some() {
        out.push(OutField {
            name: "view",
            role: Role::View,
            ty: ScalarType::U32,
        });
    }
    if cloud.truth.is_some() {
        push3(&mut out, ["tx", "ty", "tz"], [Role::Tx, Role::Ty, Role::Tz]);
    }
    out
}

/// The value of `role` at point `i` (NaN if the column is absent or short, which
/// [`check_writable`] rules out).
pub(crate) fn value(cloud: &PointCloud, role: Role, i: usize) -> f64 {
    fn get<T>(col: &Option<Vec<T>>, i: usize, f: impl Fn(&T) -> f64) -> f64 {
        col.as_ref().and_then(|c| c.get(i)).map_or(f64::NAN, f)
    }
    let pts = Some(&cloud.points);
    match role {
        Role::X => pts.and_then(|c| c.get(i)).map_or(f64::NAN, |p| p.x),
        Role::Y => pts.and_then(|c| c.get(i)).map_or(f64::NAN, |p| p.y),
        Role::Z => pts.and_then(|c| c.get(i)).map_or(f64::NAN, |p| p.z),
        Role::Nx => get(&cloud.normals, i, |v| v.x),
        Role::Ny => get(&cloud.normals, i, |v| v.y),
        Role::Nz => get(&cloud.normals, i, |v| v.z),
        Role::Ox => get(&cloud.origins, i, |p| p.x),
        Role::Oy => get(&cloud.origins, i, |p| p.y),
        Role::Oz => get(&cloud.origins, i, |p| p.z),
        Role::Label => get(&cloud.labels, i, |&l| f64::from(l)),
        Role::View => get(&cloud.views, i, |&l| f64::from(l)),
        Role::Tx => get(&cloud.truth, i, |p| p.x),
        Role::Ty => get(&cloud.truth, i, |p| p.y),
        Role::Tz => get(&cloud.truth, i, |p| p.z),
    }
}

/// Checks that every column has one entry per point and, for 32-bit output, that no
/// finite value overflows `f32` (non-finite values are written as they are).
pub(crate) fn check_writable(cloud: &PointCloud, fields: &[OutField]) -> Result<(), CloudIoError> {
    let n = cloud.len();
    let lens = [
        ("origins", cloud.origins.as_ref().map(Vec::len)),
        ("normals", cloud.normals.as_ref().map(Vec::len)),
        ("labels", cloud.labels.as_ref().map(Vec::len)),
        ("views", cloud.views.as_ref().map(Vec::len)),
        ("truth", cloud.truth.as_ref().map(Vec::len)),
    ];
    for (column, len) in lens {
        if let Some(len) = len.filter(|&l| l != n) {
            return Err(CloudIoError::file(CloudIoErrorKind::InvalidCloud(
                CloudError::ColumnLength {
                    column,
                    len,
                    points: n,
                },
            )));
        }
    }
    for f in fields.iter().filter(|f| f.ty == ScalarType::F32) {
        for i in 0..n {
            let v = value(cloud, f.role, i);
            if v.is_finite() && !(v as f32).is_finite() {
                return Err(CloudIoError::at(
                    Location::Point(i),
                    CloudIoErrorKind::NotRepresentable {
                        column: f.name,
                        value: v,
                    },
                ));
            }
        }
    }
    Ok(())
}
