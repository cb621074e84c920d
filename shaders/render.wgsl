// The 3D view: a lit, two-sided surface and a wireframe overlay, drawn into the view's own
// multisampled target, and the composite that copies the result into egui's render pass.
//
// Runs on WebGPU and on WebGL2 (eframe's fallback), so it uses only what both have: one uniform
// buffer, vertex attributes, no storage buffers. Positions and normals are vec4 per vertex (the
// GPU engine's layout, w ignored); colours are sRGB-encoded RGBA8.

// `ViewUniforms` in src/view/uniforms.rs, 160 bytes.
struct View {
    view_proj: mat4x4<f32>,
    eye: vec4<f32>,
    light: vec4<f32>,
    base_color: vec4<f32>,
    back_tint: vec4<f32>,
    wire_color: vec4<f32>,
    background: vec4<f32>,
    // Fragments where dot(clip.xyz, p) > clip.w are cut away; a zero normal cuts nothing.
    clip: vec4<f32>,
    flags: u32,
}

// Flags, as in src/view/uniforms.rs.
const VERTEX_COLORS: u32 = 1u;
const OUTPUT_LINEAR: u32 = 2u;

// Lighting, all fixed to the camera: a key light above-left of the eye shapes the surface, a
// fill light at the eye keeps what faces the viewer bright, ambient keeps the rest visible, and
// a small specular highlight shows surface relief (voxel steps, smoothing noise).
const AMBIENT: f32 = 0.07;
const KEY: f32 = 0.72;
const FILL: f32 = 0.3;
const SPECULAR: f32 = 0.22;
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
    // Opacity: the record's (a case's translucent model) times the vertex colour's (a case's
    // other structures).
    @location(3) alpha: f32,
}

@vertex
fn vs_surface(v: SurfaceVertex) -> SurfaceFragment {
    var out: SurfaceFragment;
    out.clip = view.view_proj * vec4<f32>(v.position.xyz, 1.0);
    out.world = v.position.xyz;
    out.normal = v.normal.xyz;
    if (view.flags & VERTEX_COLORS) != 0u {
        out.albedo = linear_from_srgb(v.color.rgb);
        out.alpha = v.color.a * view.base_color.a;
    } else {
        out.albedo = view.base_color.rgb;
        out.alpha = view.base_color.a;
    }
    return out;
}

@fragment
fn fs_surface(f: SurfaceFragment, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    if dot(view.clip.xyz, f.world) > view.clip.w {
        discard;
    }
    return shade(f, front);
}

// The surface where it meets the clipping plane, drawn over the image's slice there: within
// this many pixels of the plane a fragment shows its structure's colour, unlit, as the cut
// outline a radiology viewer draws on a slice.
const CUT_LINE_PIXELS: f32 = 1.5;

struct CutOutput {
    @location(0) color: vec4<f32>,
    @builtin(frag_depth) depth: f32,
}

@fragment
fn fs_surface_cut(f: SurfaceFragment, @builtin(front_facing) front: bool) -> CutOutput {
    // Distance past the plane (negative on the kept side), and its change across a pixel.
    let past = dot(view.clip.xyz, f.world) - view.clip.w;
    let band = CUT_LINE_PIXELS * fwidth(past);
    if past > 0.0 {
        discard;
    }
    var out: CutOutput;
    if -past <= band {
        // Pulled towards the eye like the wireframe, to win against the slice it lies on.
        let pulled = view.view_proj * vec4<f32>(mix(f.world, view.eye.xyz, WIRE_PULL), 1.0);
        out.depth = pulled.z / pulled.w;
        out.color = encode(f.albedo, 1.0);
    } else {
        out.depth = f.clip.z;
        out.color = shade(f, front);
    }
    return out;
}

// A closed surface cut open by the clipping plane, drawn solid, as an anatomy atlas shows a
// cut: its front faces lit as ever, and its inside, which shows only through the cut, drawn
// where the eye's ray crosses the plane (its depth there), in the structure's colour lit as a
// face turned to the removed side. What lies inside the structure behind the plane stays hidden.
const CAP_TOWARD_INSIDE: f32 = 0.01;

@fragment
fn fs_surface_capped(f: SurfaceFragment, @builtin(front_facing) front: bool) -> CutOutput {
    if dot(view.clip.xyz, f.world) > view.clip.w {
        discard;
    }
    var out: CutOutput;
    if front {
        out.depth = f.clip.z;
        out.color = shade(f, true);
        return out;
    }
    let eye = view.eye.xyz;
    let from_eye = f.world - eye;
    let across = dot(view.clip.xyz, from_eye);
    // Along the ray from the eye to this inside point, where it meets the plane.
    var t = 1.0;
    if abs(across) > 1e-12 {
        t = clamp((view.clip.w - dot(view.clip.xyz, eye)) / across, 0.0, 1.0);
    }
    var cap = f;
    cap.world = eye + t * from_eye;
    cap.normal = view.clip.xyz;
    let at = view.view_proj * vec4<f32>(cap.world, 1.0);
    // Nested structures cut together cap at the same plane: the inner one, whose inside lies
    // nearer, must win, so each cap lies a little towards its own inside.
    out.depth = mix(at.z / at.w, f.clip.z, CAP_TOWARD_INSIDE);
    out.color = shade(cap, true);
    return out;
}

// A translucent surface: where the clipping plane cuts it, its cut outline in its own colour,
// opaque, so that the cut reads through it (a translucent structure gets no cap).
@fragment
fn fs_translucent(f: SurfaceFragment, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    let past = dot(view.clip.xyz, f.world) - view.clip.w;
    let band = CUT_LINE_PIXELS * fwidth(past);
    if past > 0.0 {
        discard;
    }
    let cutting = any(view.clip.xyz != vec3<f32>(0.0));
    if cutting && -past <= band {
        return encode(f.albedo, 1.0);
    }
    return shade(f, front);
}

fn shade(f: SurfaceFragment, front: bool) -> vec4<f32> {
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
    let to_light = view.light.xyz;
    let key = max(dot(n, to_light), 0.0);
    let fill = max(dot(n, to_eye), 0.0);
    // Blinn-Phong highlight of the key light, only where the key light reaches.
    let half_vector = normalize(to_light + to_eye);
    let highlight = select(0.0, pow(max(dot(n, half_vector), 0.0), SHININESS), key > 0.0);
    let rgb = albedo * (AMBIENT + KEY * key + FILL * fill) + vec3<f32>(SPECULAR * highlight);
    return encode(rgb, f.alpha);
}

// Wireframe lines lie exactly on the surface, so each is moved this fraction of its distance
// towards the eye to win the depth test against it. Relative to the distance, the pull covers
// the surface's depth change across a pixel for surfaces up to ~75 degrees from facing the eye
// (in a view 750 pixels high), while lines behind anything thicker than 0.3% of the viewing
// distance stay hidden. (Depth bias on the surface would do the same, but it lets back faces
// win at silhouettes.)
const WIRE_PULL: f32 = 0.003;

struct WireFragment {
    @builtin(position) clip: vec4<f32>,
    // Where the line lies on the surface, for the clipping plane.
    @location(0) world: vec3<f32>,
}

@vertex
fn vs_wire(@location(0) position: vec4<f32>) -> WireFragment {
    let pulled = mix(position.xyz, view.eye.xyz, WIRE_PULL);
    return WireFragment(view.view_proj * vec4<f32>(pulled, 1.0), position.xyz);
}

@fragment
fn fs_wire(f: WireFragment) -> @location(0) vec4<f32> {
    if dot(view.clip.xyz, f.world) > view.clip.w {
        discard;
    }
    return encode(view.wire_color.rgb, view.wire_color.a);
}

// The image's slice on the clipping plane: a quad across the image's box, each fragment the
// image's grey level there (trilinear), opaque. Group 1 as `slice_layout` in
// src/app/viewer/pipelines.rs (bindings from 1: the composite's group has binding 0).

// `SliceUniforms` in src/view/slice.rs, 128 bytes.
struct Slice {
    world_to_texture: mat4x4<f32>,
    corners: array<vec4<f32>, 4>,
}

@group(1) @binding(1) var<uniform> slice: Slice;
@group(1) @binding(2) var slice_image: texture_3d<f32>;
@group(1) @binding(3) var slice_sampler: sampler;

struct SliceFragment {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
}

// Two triangles: corners 0, 1, 2 and 0, 2, 3.
@vertex
fn vs_slice(@builtin(vertex_index) index: u32) -> SliceFragment {
    var corner = index;
    if index >= 3u {
        corner = select(index - 2u, 0u, index == 3u);
    }
    let p = slice.corners[corner].xyz;
    return SliceFragment(view.view_proj * vec4<f32>(p, 1.0), p);
}

@fragment
fn fs_slice(f: SliceFragment) -> @location(0) vec4<f32> {
    let t = (slice.world_to_texture * vec4<f32>(f.world, 1.0)).xyz;
    // Level 0 explicitly: no derivatives needed after the discard.
    let grey = textureSampleLevel(slice_image, slice_sampler, t, 0.0).r;
    if any(t < vec3<f32>(0.0)) || any(t > vec3<f32>(1.0)) {
        discard;
    }
    // Grey levels are display values, as a radiology viewer shows them.
    return encode(linear_from_srgb(vec3<f32>(grey)), 1.0);
}

// Composite: egui's render pass has no multisampling on the web, so the view is drawn with 4x
// MSAA into its own target and this copies the resolved image into egui's pass, one texel per
// pixel (the viewport is the view's rectangle). Colours are already encoded and premultiplied.
// It lays them over the view's background itself, so no other pass fills the view's pixels
// (a software rasteriser pays for every pass over them).

@group(1) @binding(0) var frame: texture_2d<f32>;

struct CompositeFragment {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
}

// One triangle covering the viewport: vertices (-1, -1), (3, -1), (-1, 3).
@vertex
fn vs_composite(@builtin(vertex_index) index: u32) -> CompositeFragment {
    let xy = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u)) * 2.0 - 1.0;
    var out: CompositeFragment;
    out.clip = vec4<f32>(xy, 0.0, 1.0);
    out.uv = vec2<f32>(xy.x + 1.0, 1.0 - xy.y) * 0.5;
    return out;
}

@fragment
fn fs_composite(f: CompositeFragment) -> @location(0) vec4<f32> {
    // Loaded, not sampled: texel for pixel, and a software rasteriser filters nothing.
    let texel = vec2<i32>(f.uv * vec2<f32>(textureDimensions(frame)));
    let view_color = textureLoad(frame, texel, 0);
    let background = encode(view.background.rgb, 1.0).rgb;
    return vec4<f32>(view_color.rgb + background * (1.0 - view_color.a), 1.0);
}
