// Shading (seed 002): Blinn–Phong per light of the fragment's light-grid
// cell, attenuation i / (d³ + 1), emission, a small ambient term, gamma;
// base-colour textures and the alpha test (cutoff in the prepass and the
// shading pass alike, seed 002's "transparence").

struct Material {
    // rgb: base colour (times the texture), w: alpha cutoff (0: opaque).
    colour: vec4<f32>,
    // rgb: emission, w: Blinn–Phong exponent.
    emission_shininess: vec4<f32>,
    // x: base texture layer, y: alpha texture layer (-1: none).
    layers: vec4<i32>,
}

struct Light {
    position_intensity: vec4<f32>,
    colour: vec4<f32>,
}

@group(0) @binding(4) var<storage, read> materials: array<Material>;
@group(0) @binding(5) var<storage, read> lights: array<Light>;
@group(0) @binding(6) var<storage, read> ranges: array<vec2<u32>>;
@group(0) @binding(7) var<storage, read> light_indices: array<u32>;
@group(0) @binding(8) var textures: texture_2d_array<f32>;
@group(0) @binding(9) var texture_sampler: sampler;

const AMBIENT: f32 = 0.06;
const SPECULAR: f32 = 0.25;
const HEADLIGHT: f32 = 0.85;

struct VsOut {
    @builtin(position) @invariant clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) @interpolate(flat) material: u32,
    @location(3) uv: vec2<f32>,
}

@vertex
fn vs(@location(0) position: vec3<f32>, @location(1) material: u32, @location(2) normal: vec3<f32>, @location(3) uv: vec2<f32>) -> VsOut {
    var out: VsOut;
    out.clip = frame.view_proj * vec4<f32>(position, 1.0);
    out.world = position;
    out.normal = normal;
    out.material = material;
    out.uv = uv;
    return out;
}

// The base texture's colour (white without one). Sampled at level 0: the
// array has no mipmaps, and the explicit level keeps the call legal where
// control flow is not uniform.
fn base_texel(m: Material, uv: vec2<f32>) -> vec4<f32> {
    if m.layers.x < 0 {
        return vec4<f32>(1.0);
    }
    return textureSampleLevel(textures, texture_sampler, uv, m.layers.x, 0.0);
}

// True where the alpha test cuts the surface out: the alpha texture's
// alpha, else the base texture's, below the material's cutoff.
fn cut_out(m: Material, uv: vec2<f32>, base: vec4<f32>) -> bool {
    if m.colour.w <= 0.0 {
        return false;
    }
    var alpha = base.a;
    if m.layers.y >= 0 {
        alpha = textureSampleLevel(textures, texture_sampler, uv, m.layers.y, 0.0).a;
    }
    return alpha < m.colour.w;
}

// The depth-only passes (Z-prepass, occlusion depth): the alpha test alone.
@fragment
fn fs_depth(in: VsOut) {
    let m = materials[in.material];
    if cut_out(m, in.uv, base_texel(m, in.uv)) {
        discard;
    }
}

fn to_srgb(c: vec3<f32>) -> vec3<f32> {
    let x = clamp(c, vec3<f32>(0.0), vec3<f32>(1.0));
    return select(1.055 * pow(x, vec3<f32>(1.0 / 2.4)) - 0.055, 12.92 * x, x <= vec3<f32>(0.0031308));
}

@fragment
fn fs(in: VsOut) -> @location(0) vec4<f32> {
    let m = materials[in.material];
    let texel = base_texel(m, in.uv);
    if cut_out(m, in.uv, texel) {
        discard;
    }
    let v = normalize(frame.eye.xyz - in.world);
    var n = normalize(in.normal);
    if dot(n, v) < 0.0 {
        n = -n; // two-sided: meshes are not always consistently oriented
    }
    let albedo = m.colour.rgb * texel.rgb;
    let shininess = m.emission_shininess.w;
    var c = m.emission_shininess.rgb + albedo * AMBIENT;
    let cellf = clamp(floor((in.world - frame.grid_lo.xyz) / frame.grid_cell.xyz), vec3<f32>(0.0), vec3<f32>(31.0));
    let cell = u32(cellf.x) + 32u * (u32(cellf.y) + 32u * u32(cellf.z));
    let r = ranges[cell];
    if (frame.params.z & 4u) != 0u {
        // The light grid itself: the cell's list length, blue (none) to red (the most).
        let t = clamp(f32(r.y) / max(frame.grid_cell.w, 1.0), 0.0, 1.0);
        let heat = clamp(vec3<f32>(1.5 - abs(4.0 * t - 3.0), 1.5 - abs(4.0 * t - 2.0), 1.5 - abs(4.0 * t - 1.0)), vec3<f32>(0.0), vec3<f32>(1.0));
        let shade = 0.55 + 0.45 * max(dot(n, v), 0.0);
        return vec4<f32>(heat * shade, 1.0);
    }
    for (var k = 0u; k < r.y; k++) {
        let light = lights[light_indices[r.x + k]];
        let to = light.position_intensity.xyz - in.world;
        let dist = length(to);
        let l = to / max(dist, 1e-20);
        let d = dist / frame.grid_lo.w;
        let att = light.position_intensity.w / (d * d * d + 1.0);
        let h = normalize(l + v);
        let diffuse = albedo * max(dot(n, l), 0.0);
        let specular = SPECULAR * pow(max(dot(n, h), 0.0), shininess) * f32(dot(n, l) > 0.0);
        c += light.colour.rgb * att * (diffuse + vec3<f32>(specular));
    }
    if (frame.params.z & 2u) != 0u {
        // No lights in the scene: a light at the eye (l = h = v).
        let nv = max(dot(n, v), 0.0);
        c += HEADLIGHT * albedo * nv + vec3<f32>(SPECULAR * pow(nv, shininess));
    }
    if (frame.params.z & 1u) != 0u {
        c = to_srgb(c);
    }
    return vec4<f32>(clamp(c, vec3<f32>(0.0), vec3<f32>(1.0)), 1.0);
}
