// Lines: each segment an instanced screen-space quad `width` pixels wide with square caps,
// clipped against the near plane so that segments passing behind the eye stay right.

struct LineIn {
    @builtin(vertex_index) vi: u32,
    @location(0) a: vec3<f32>,
    @location(1) width: f32,
    @location(2) b: vec3<f32>,
    @location(3) color: vec4<f32>,
};

struct LineOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) color: vec3<f32>,
};

@vertex
fn vs_line(in: LineIn) -> LineOut {
    var out: LineOut;
    out.color = srgb_to_linear(in.color.rgb);
    var ca = globals.view_proj * vec4<f32>(in.a, 1.0);
    var cb = globals.view_proj * vec4<f32>(in.b, 1.0);
    if (ca.z < 0.0 && cb.z < 0.0) {
        // Wholly in front of the near plane: a degenerate quad outside the view.
        out.clip = vec4<f32>(2.0, 2.0, 2.0, 1.0);
        return out;
    }
    if (ca.z < 0.0) {
        ca = mix(ca, cb, ca.z / (ca.z - cb.z));
    }
    if (cb.z < 0.0) {
        cb = mix(cb, ca, cb.z / (cb.z - ca.z));
    }
    let half_vp = 0.5 * globals.viewport.xy;
    let sa = ca.xy / ca.w * half_vp;
    let sb = cb.xy / cb.w * half_vp;
    var dir = sb - sa;
    let len = length(dir);
    if (len < 1e-6) {
        dir = vec2<f32>(1.0, 0.0);
    } else {
        dir = dir / len;
    }
    let normal = vec2<f32>(-dir.y, dir.x);
    let corner = quad_corner(in.vi % 6u);
    let t = 0.5 * (corner.x + 1.0);
    var c = select(ca, cb, t > 0.5);
    let half_width = 0.5 * in.width;
    let offset_px = normal * corner.y * half_width + dir * corner.x * half_width;
    c = vec4<f32>(c.xy + offset_px / half_vp * c.w, c.zw);
    out.clip = c;
    return out;
}

@fragment
fn fs_line(in: LineOut) -> @location(0) vec4<f32> {
    return vec4<f32>(in.color, 1.0);
}
