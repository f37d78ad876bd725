// Voxels: a unit cube (per-vertex buffer) instanced at each centre and size, lit per face,
// with darkened edges about a pixel wide.

struct CubeIn {
    @location(0) local: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) center: vec3<f32>,
    @location(3) size: f32,
    @location(4) color: vec4<f32>,
    @location(5) outline: f32,
};

struct CubeOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) color: vec3<f32>,
    @location(3) local: vec3<f32>,
    @location(4) outline: f32,
};

@vertex
fn vs_voxel(in: CubeIn) -> CubeOut {
    var out: CubeOut;
    let world = in.center + in.local * in.size;
    out.clip = globals.view_proj * vec4<f32>(world, 1.0);
    out.world = world;
    out.normal = in.normal;
    out.color = srgb_to_linear(in.color.rgb);
    out.local = in.local;
    out.outline = in.outline;
    return out;
}

@fragment
fn fs_voxel(in: CubeOut) -> @location(0) vec4<f32> {
    let n = normalize(in.normal);
    var lit = shade(in.color, n, in.world);
    // Distance (cube units) to the nearest edge of this face: the largest in-face coordinate.
    let a = abs(in.local);
    let in_face = abs(n) < vec3<f32>(0.5);
    let m = max(max(select(0.0, a.x, in_face.x), select(0.0, a.y, in_face.y)), select(0.0, a.z, in_face.z));
    let d = 0.5 - m;
    // Cube units per pixel.
    let fw = fwidth(in.local);
    let px = max(max(fw.x, fw.y), fw.z);
    let band = min(px, 0.08);
    let edge = 1.0 - smoothstep(band, band + px, d);
    // Fade the outline out on cubes too small for it to mean anything.
    let strength = in.outline * (1.0 - smoothstep(0.15, 0.4, px));
    lit = lit * (1.0 - strength * edge);
    return vec4<f32>(lit, 1.0);
}
