// Per-frame uniforms and the lighting shared by every drawable (prepended to each shader).

struct Globals {
    view_proj: mat4x4<f32>,
    eye: vec4<f32>,
    // xyz: world direction towards the key light; w: its intensity.
    key: vec4<f32>,
    // xyz: world direction towards the fill light; w: its intensity.
    fill: vec4<f32>,
    // x: ambient, y: specular strength, z: shininess.
    params: vec4<f32>,
    // x, y: size in pixels; z, w: their inverses.
    viewport: vec4<f32>,
};

@group(0) @binding(0) var<uniform> globals: Globals;

fn srgb_to_linear(c: vec3<f32>) -> vec3<f32> {
    let lo = c / 12.92;
    let hi = pow((c + vec3<f32>(0.055)) / 1.055, vec3<f32>(2.4));
    return select(hi, lo, c <= vec3<f32>(0.04045));
}

// Lit colour (linear light) of a surface of linear colour `albedo` with unit normal `n`
// facing the viewer, at world position `p`.
fn shade(albedo: vec3<f32>, n: vec3<f32>, p: vec3<f32>) -> vec3<f32> {
    let v = normalize(globals.eye.xyz - p);
    let lk = globals.key.xyz;
    let lf = globals.fill.xyz;
    let nk = dot(n, lk);
    let diffuse = globals.params.x
        + globals.key.w * max(nk, 0.0)
        + globals.fill.w * max(dot(n, lf), 0.0);
    let h = normalize(lk + v);
    let spec = select(0.0, globals.params.y * pow(max(dot(n, h), 0.0), globals.params.z), nk > 0.0);
    return albedo * diffuse + vec3<f32>(spec);
}

// The interpolated normal turned towards the viewer, judged against the true geometric
// facing of the fragment's triangle (so winding order does not matter).
fn facing_normal(normal: vec3<f32>, p: vec3<f32>) -> vec3<f32> {
    var n = normalize(normal);
    var g = cross(dpdx(p), dpdy(p));
    let v = globals.eye.xyz - p;
    if (dot(g, v) < 0.0) {
        g = -g;
    }
    if (dot(n, g) < 0.0) {
        n = -n;
    }
    return n;
}

// Corner `vi` (0..6) of a quad made of two triangles, in [-1, 1]².
fn quad_corner(vi: u32) -> vec2<f32> {
    let x = select(-1.0, 1.0, vi == 1u || vi == 2u || vi == 4u);
    let y = select(-1.0, 1.0, vi == 2u || vi == 4u || vi == 5u);
    return vec2<f32>(x, y);
}
