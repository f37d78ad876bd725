// Points: instanced screen-aligned quads shaded as small balls, with an anti-aliased rim
// (alpha to coverage when multisampling, a hard cut otherwise).

struct PointIn {
    @builtin(vertex_index) vi: u32,
    @location(0) position: vec3<f32>,
    @location(1) size: f32,
    @location(2) color: vec4<f32>,
};

struct PointOut {
    @builtin(position) clip: vec4<f32>,
    // Position in the quad, in sprite radii (the disc edge is at 1).
    @location(0) corner: vec2<f32>,
    @location(1) color: vec3<f32>,
    @location(2) radius_px: f32,
};

@vertex
fn vs_point(in: PointIn) -> PointOut {
    var out: PointOut;
    let radius = 0.5 * in.size;
    // Half a pixel of margin for the anti-aliased rim.
    let extent = radius + 0.5;
    let corner = quad_corner(in.vi % 6u);
    var clip = globals.view_proj * vec4<f32>(in.position, 1.0);
    clip = vec4<f32>(clip.xy + corner * extent * 2.0 * globals.viewport.zw * clip.w, clip.zw);
    out.clip = clip;
    out.corner = corner * extent / radius;
    out.color = srgb_to_linear(in.color.rgb);
    out.radius_px = radius;
    return out;
}

@fragment
fn fs_point(in: PointOut) -> @location(0) vec4<f32> {
    let r = length(in.corner);
    let coverage = clamp((1.0 - r) * in.radius_px + 0.5, 0.0, 1.0);
    if (coverage <= POINT_DISCARD_BELOW) {
        discard;
    }
    let nz = sqrt(max(1.0 - r * r, 0.0));
    let lit = in.color * (0.72 + 0.28 * nz);
    return vec4<f32>(lit, coverage);
}
