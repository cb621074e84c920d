// The 3D view, drawn inside egui's render pass: a lit, two-sided surface and a wireframe overlay.
//
// Runs on WebGPU and on WebGL2 (eframe's fallback), so it uses only what both have: one uniform
// buffer, vertex attributes, no storage buffers. Positions and normals are vec4 per vertex (the
// GPU engine's layout, w ignored); colours are sRGB-encoded RGBA8.

// `ViewUniforms` in src/view/uniforms.rs, 144 bytes.
struct View {
    view_proj: mat4x4<f32>,
    eye: vec4<f32>,
    base_color: vec4<f32>,
    back_tint: vec4<f32>,
    wire_color: vec4<f32>,
    flags: u32,
}

// Flags, as in src/view/uniforms.rs.
const VERTEX_COLORS: u32 = 1u;
const OUTPUT_LINEAR: u32 = 2u;

// Lighting: a headlight at the eye. Ambient keeps surfaces facing away from it visible; a
// small specular highlight shows surface relief (voxel steps, smoothing noise).
const AMBIENT: f32 = 0.16;
const DIFFUSE: f32 = 0.84;
const SPECULAR: f32 = 0.18;
const SHININESS: f32 = 40.0;
// Back faces are shaded a little darker, besides their tint.
const BACK_SHADE: f32 = 0.8;

@group(0) @binding(0) var<uniform> view: View;

fn linear_from_srgb(srgb: vec3<f32>) -> vec3<f32> {
    let low = srgb / 12.92;
    let high = pow((srgb + vec3<f32>(0.055)) / 1.055, vec3<f32>(2.4));
    return select(high, low, srgb <= vec3<f32>(0.04045));
}

fn srgb_from_linear(linear: vec3<f32>) -> vec3<f32> {
    let low = linear * 12.92;
    let high = 1.055 * pow(linear, vec3<f32>(1.0 / 2.4)) - 0.055;
    return select(high, low, linear <= vec3<f32>(0.0031308));
}

// Linear RGB and straight alpha to what the framebuffer expects, premultiplied as egui blends:
// linear for an sRGB framebuffer (the hardware encodes), sRGB-encoded otherwise.
fn encode(rgb: vec3<f32>, alpha: f32) -> vec4<f32> {
    let c = clamp(rgb, vec3<f32>(0.0), vec3<f32>(1.0));
    if (view.flags & OUTPUT_LINEAR) != 0u {
        return vec4<f32>(c * alpha, alpha);
    }
    return vec4<f32>(srgb_from_linear(c) * alpha, alpha);
}

struct SurfaceVertex {
    @location(0) position: vec4<f32>,
    @location(1) normal: vec4<f32>,
    @location(2) color: vec4<f32>,
}

struct SurfaceFragment {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) albedo: vec3<f32>,
}

@vertex
fn vs_surface(v: SurfaceVertex) -> SurfaceFragment {
    var out: SurfaceFragment;
    out.clip = view.view_proj * vec4<f32>(v.position.xyz, 1.0);
    out.world = v.position.xyz;
    out.normal = v.normal.xyz;
    if (view.flags & VERTEX_COLORS) != 0u {
        out.albedo = linear_from_srgb(v.color.rgb);
    } else {
        out.albedo = view.base_color.rgb;
    }
    return out;
}

@fragment
fn fs_surface(f: SurfaceFragment, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    let to_eye = normalize(view.eye.xyz - f.world);
    // Vertices without area have a zero normal: light them as if facing the eye.
    var n = to_eye;
    let length_n = length(f.normal);
    if length_n > 1e-6 {
        n = f.normal / length_n;
    }
    var albedo = f.albedo;
    if !front {
        // Two-sided: the inside of an open mesh is lit from its own side, tinted.
        n = -n;
        albedo = mix(albedo, view.back_tint.rgb, view.back_tint.a) * BACK_SHADE;
    }
    // With the light at the eye, the half vector is the direction to the eye.
    let facing = max(dot(n, to_eye), 0.0);
    let rgb = albedo * (AMBIENT + DIFFUSE * facing) + vec3<f32>(SPECULAR * pow(facing, SHININESS));
    return encode(rgb, 1.0);
}

@vertex
fn vs_wire(@location(0) position: vec4<f32>) -> @builtin(position) vec4<f32> {
    return view.view_proj * vec4<f32>(position.xyz, 1.0);
}

@fragment
fn fs_wire() -> @location(0) vec4<f32> {
    return encode(view.wire_color.rgb, view.wire_color.a);
}
