// The ray spray's points (seed 002, "Ray-tracing"; Rust: `spray.rs`). Each
// point carries what does not depend on the viewer — albedo, emission and
// the light term of its light samples (Lambert term, attenuation, shadow
// rays) — and the view's part is computed here every frame: the Lambert
// term towards the viewer and the attenuation i / (d³ + 1) towards it, with
// d in view units (the eye's distance to its target, `frame.eye.w`) and
// i = 2, so that a point at the target keeps its stored brightness.
// Appended to shade.wgsl (its to_srgb and HEADLIGHT).

struct PointOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) albedo: vec3<f32>,
    @location(3) light: vec3<f32>,
    @location(4) emission: vec3<f32>,
}

// Points are drawn over the surface they lie on: moved towards the eye by
// this many attenuation units before projection.
const POINT_LIFT: f32 = 0.01;

@vertex
fn vs_point(
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) albedo: vec3<f32>,
    @location(3) light: vec3<f32>,
    @location(4) emission: vec3<f32>,
) -> PointOut {
    var out: PointOut;
    let towards = frame.eye.xyz - position;
    let lifted = position + towards / max(length(towards), 1e-20) * (POINT_LIFT * frame.grid_lo.w);
    out.clip = frame.view_proj * vec4<f32>(lifted, 1.0);
    out.world = position;
    out.normal = normal;
    out.albedo = albedo;
    out.light = light;
    out.emission = emission;
    return out;
}

@fragment
fn fs_point(in: PointOut) -> @location(0) vec4<f32> {
    let to_eye = frame.eye.xyz - in.world;
    let dist = length(to_eye);
    let v = to_eye / max(dist, 1e-20);
    let lambert = max(dot(normalize(in.normal), v), 0.0);
    let d = dist / max(frame.eye.w, 1e-20);
    let att = 2.0 / (d * d * d + 1.0);
    var c = in.emission + in.albedo * in.light * lambert * att;
    if (frame.params.z & 2u) != 0u {
        // No lights in the scene: the head-light of the shading pass.
        c += HEADLIGHT * in.albedo * lambert;
    }
    if (frame.params.z & 1u) != 0u {
        c = to_srgb(c);
    }
    return vec4<f32>(clamp(c, vec3<f32>(0.0), vec3<f32>(1.0)), 1.0);
}
