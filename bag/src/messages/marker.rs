//! `visualization_msgs`: [`MarkerArray`], [`Marker`] (every Humble/Jazzy field) and its
//! [`UVCoordinate`] and [`MeshFile`].

use super::{
    CdrStruct, ColorRGBA, CompressedImage, Duration, Header, Point, Pose, Vector3, read_seq,
    ros_message, write_seq,
};
use crate::cdr::{CdrReader, CdrWriter};
use crate::error::CdrError;

/// `visualization_msgs/msg/UVCoordinate`: a texture coordinate.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct UVCoordinate {
    /// u.
    pub u: f32,
    /// v.
    pub v: f32,
}

impl CdrStruct for UVCoordinate {
    fn write_cdr(&self, w: &mut CdrWriter) {
        w.f32(self.u);
        w.f32(self.v);
    }
    fn read_cdr(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        Ok(Self {
            u: r.f32()?,
            v: r.f32()?,
        })
    }
}

ros_message!(
    UVCoordinate,
    "visualization_msgs/msg/UVCoordinate",
    "RIHS01_f27f7ed21fe360c6066944f856b801a0c0d1e94e815b6886444b42d90b196a26",
    "float32 u\nfloat32 v\n",
    []
);

/// `visualization_msgs/msg/MeshFile`: an embedded mesh file.
#[derive(Debug, Clone, Default, PartialEq, Eq, Hash)]
pub struct MeshFile {
    /// The file's name (its extension tells the format).
    pub filename: String,
    /// The file's bytes.
    pub data: Vec<u8>,
}

impl CdrStruct for MeshFile {
    fn write_cdr(&self, w: &mut CdrWriter) {
        w.string(&self.filename);
        w.bytes(&self.data);
    }
    fn read_cdr(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        Ok(Self {
            filename: r.string()?,
            data: r.bytes()?,
        })
    }
}

ros_message!(
    MeshFile,
    "visualization_msgs/msg/MeshFile",
    "RIHS01_7710ece15a148fb7c9b546364cfb215bb06098087bd6394fe5b73a493508f8c4",
    "string filename\nuint8[] data\n",
    []
);

/// `visualization_msgs/msg/Marker` (Humble and Jazzy; wire-identical).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Marker {
    /// Stamp and frame.
    pub header: Header,
    /// Namespace.
    pub ns: String,
    /// Id within the namespace.
    pub id: i32,
    /// One of `Marker::ARROW..TRIANGLE_LIST`.
    pub r#type: i32,
    /// `Marker::ADD`, `DELETE` or `DELETEALL`.
    pub action: i32,
    /// Pose of the marker's frame.
    pub pose: Pose,
    /// Size.
    pub scale: Vector3,
    /// Colour (when `colors` is empty).
    pub color: ColorRGBA,
    /// How long it lives (0: forever).
    pub lifetime: Duration,
    /// Whether it follows its frame.
    pub frame_locked: bool,
    /// Points of list types.
    pub points: Vec<Point>,
    /// Per-point colours.
    pub colors: Vec<ColorRGBA>,
    /// Texture resource URI.
    pub texture_resource: String,
    /// Embedded texture.
    pub texture: CompressedImage,
    /// Texture coordinates.
    pub uv_coordinates: Vec<UVCoordinate>,
    /// Text of `TEXT_VIEW_FACING`.
    pub text: String,
    /// Mesh resource URI of `MESH_RESOURCE`.
    pub mesh_resource: String,
    /// Embedded mesh.
    pub mesh_file: MeshFile,
    /// Whether to use the mesh's materials.
    pub mesh_use_embedded_materials: bool,
}

impl Marker {
    /// An arrow.
    pub const ARROW: i32 = 0;
    /// A box.
    pub const CUBE: i32 = 1;
    /// A sphere.
    pub const SPHERE: i32 = 2;
    /// A cylinder.
    pub const CYLINDER: i32 = 3;
    /// A polyline.
    pub const LINE_STRIP: i32 = 4;
    /// Segments, two points each.
    pub const LINE_LIST: i32 = 5;
    /// A box per point.
    pub const CUBE_LIST: i32 = 6;
    /// A sphere per point.
    pub const SPHERE_LIST: i32 = 7;
    /// Points.
    pub const POINTS: i32 = 8;
    /// Text facing the viewer.
    pub const TEXT_VIEW_FACING: i32 = 9;
    /// A mesh.
    pub const MESH_RESOURCE: i32 = 10;
    /// Triangles, three points each.
    pub const TRIANGLE_LIST: i32 = 11;
    /// Add or modify.
    pub const ADD: i32 = 0;
    /// Add or modify.
    pub const MODIFY: i32 = 0;
    /// Delete this marker.
    pub const DELETE: i32 = 2;
    /// Delete every marker.
    pub const DELETEALL: i32 = 3;
}

impl CdrStruct for Marker {
    fn write_cdr(&self, w: &mut CdrWriter) {
        self.header.write_cdr(w);
        w.string(&self.ns);
        w.i32(self.id);
        w.i32(self.r#type);
        w.i32(self.action);
        self.pose.write_cdr(w);
        self.scale.write_cdr(w);
        self.color.write_cdr(w);
        self.lifetime.write_cdr(w);
        w.bool(self.frame_locked);
        write_seq(w, &self.points);
        write_seq(w, &self.colors);
        w.string(&self.texture_resource);
        self.texture.write_cdr(w);
        write_seq(w, &self.uv_coordinates);
        w.string(&self.text);
        w.string(&self.mesh_resource);
        self.mesh_file.write_cdr(w);
        w.bool(self.mesh_use_embedded_materials);
    }
    fn read_cdr(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        Ok(Self {
            header: Header::read_cdr(r)?,
            ns: r.string()?,
            id: r.i32()?,
            r#type: r.i32()?,
            action: r.i32()?,
            pose: Pose::read_cdr(r)?,
            scale: Vector3::read_cdr(r)?,
            color: ColorRGBA::read_cdr(r)?,
            lifetime: Duration::read_cdr(r)?,
            frame_locked: r.bool()?,
            points: read_seq(r, 24)?,
            colors: read_seq(r, 16)?,
            texture_resource: r.string()?,
            texture: CompressedImage::read_cdr(r)?,
            uv_coordinates: read_seq(r, 8)?,
            text: r.string()?,
            mesh_resource: r.string()?,
            mesh_file: MeshFile::read_cdr(r)?,
            mesh_use_embedded_materials: r.bool()?,
        })
    }
}

ros_message!(
    Marker,
    "visualization_msgs/msg/Marker",
    "RIHS01_45b13ccf791f225962bf74e746f9644518855d783a6f42ba0cc14fde2b4f3ce0",
    "int32 ARROW=0\nint32 CUBE=1\nint32 SPHERE=2\nint32 CYLINDER=3\nint32 LINE_STRIP=4\n\
     int32 LINE_LIST=5\nint32 CUBE_LIST=6\nint32 SPHERE_LIST=7\nint32 POINTS=8\n\
     int32 TEXT_VIEW_FACING=9\nint32 MESH_RESOURCE=10\nint32 TRIANGLE_LIST=11\nint32 ADD=0\n\
     int32 MODIFY=0\nint32 DELETE=2\nint32 DELETEALL=3\nstd_msgs/Header header\nstring ns\n\
     int32 id\nint32 type\nint32 action\ngeometry_msgs/Pose pose\n\
     geometry_msgs/Vector3 scale\nstd_msgs/ColorRGBA color\n\
     builtin_interfaces/Duration lifetime\nbool frame_locked\ngeometry_msgs/Point[] points\n\
     std_msgs/ColorRGBA[] colors\nstring texture_resource\n\
     sensor_msgs/CompressedImage texture\n\
     visualization_msgs/UVCoordinate[] uv_coordinates\nstring text\nstring mesh_resource\n\
     visualization_msgs/MeshFile mesh_file\nbool mesh_use_embedded_materials\n",
    [
        Header,
        Pose,
        Vector3,
        ColorRGBA,
        Duration,
        Point,
        ColorRGBA,
        CompressedImage,
        UVCoordinate,
        MeshFile
    ]
);

/// `visualization_msgs/msg/MarkerArray`: markers published together.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MarkerArray {
    /// The markers.
    pub markers: Vec<Marker>,
}

impl CdrStruct for MarkerArray {
    fn write_cdr(&self, w: &mut CdrWriter) {
        write_seq(w, &self.markers);
    }
    fn read_cdr(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        Ok(Self {
            markers: read_seq(r, 200)?,
        })
    }
}

ros_message!(
    MarkerArray,
    "visualization_msgs/msg/MarkerArray",
    "RIHS01_86cb8800b6fb05b5eff1abd7a56f62a5641d3ae9a1c29e78e67e704f1d067dcf",
    "visualization_msgs/Marker[] markers\n",
    [Marker]
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::messages::RosMessage;

    #[test]
    fn one_point_cube_list_is_253_bytes() {
        let m = MarkerArray {
            markers: vec![Marker {
                r#type: Marker::CUBE_LIST,
                points: vec![Point {
                    x: 1.0,
                    y: 2.0,
                    z: 3.0,
                }],
                ..Default::default()
            }],
        };
        let b = m.encode();
        assert_eq!(b.len(), 253);
        assert_eq!(MarkerArray::decode(&b).unwrap(), m);
        assert_eq!(MarkerArray::schema_text().len(), 2504);
    }
}
