// The statistics overlay: 8×8 glyphs (font8x8's ASCII set, one texel per
// pixel of a 1024×8 atlas) drawn at a whole-number scale from the
// picture's top-left corner, white on a dark box. One instance per glyph,
// four vertices each (a triangle strip).

@group(0) @binding(1) var font: texture_2d<f32>;

const GLYPH_SCALE: f32 = 2.0;

struct GlyphOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) local: vec2<f32>,
    @location(1) @interpolate(flat) code: u32,
}

@vertex
fn vs_text(@builtin(vertex_index) v: u32, @location(0) at: vec2<f32>, @location(1) code: u32) -> GlyphOut {
    let corner = vec2<f32>(f32(v & 1u), f32(v >> 1u));
    let size = vec2<f32>(f32(frame.params.w & 0xffffu), f32(frame.params.w >> 16u));
    let px = at + corner * (8.0 * GLYPH_SCALE);
    var out: GlyphOut;
    out.clip = vec4<f32>(px.x / size.x * 2.0 - 1.0, 1.0 - px.y / size.y * 2.0, 0.0, 1.0);
    out.local = corner * 8.0;
    out.code = code;
    return out;
}

@fragment
fn fs_text(in: GlyphOut) -> @location(0) vec4<f32> {
    let p = vec2<u32>(clamp(floor(in.local), vec2<f32>(0.0), vec2<f32>(7.0)));
    let bit = textureLoad(font, vec2<u32>(in.code * 8u + p.x, p.y), 0).r;
    if bit > 0.5 {
        return vec4<f32>(1.0, 1.0, 1.0, 1.0);
    }
    return vec4<f32>(0.05, 0.05, 0.06, 1.0);
}
