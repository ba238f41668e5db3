// The light grid built on the GPU (lights.rs): count each cell's lights,
// one scan into ranges, then fill each cell's list in light order.

struct Light {
    position_intensity: vec4<f32>,
    // rgb: colour, w: squared reach in world units.
    colour: vec4<f32>,
}

struct GridParams {
    lo: vec4<f32>,
    cell: vec4<f32>,
    // x: lights.
    counts: vec4<u32>,
}

const GRID: u32 = 32u;
const CELLS: u32 = 32768u;

@group(0) @binding(0) var<uniform> gp: GridParams;
@group(0) @binding(1) var<storage, read> lights: array<Light>;
@group(0) @binding(2) var<storage, read_write> ranges: array<vec2<u32>>;
@group(0) @binding(3) var<storage, read_write> indices: array<u32>;
@group(0) @binding(4) var<storage, read_write> total: array<u32>;

fn cell_lo(c: u32) -> vec3<f32> {
    let at = vec3<f32>(f32(c % GRID), f32((c / GRID) % GRID), f32(c / (GRID * GRID)));
    return gp.lo.xyz + gp.cell.xyz * at;
}

fn reaches(l: u32, clo: vec3<f32>, chi: vec3<f32>) -> bool {
    let p = lights[l].position_intensity.xyz;
    let d = clamp(p, clo, chi) - p;
    return d.x * d.x + d.y * d.y + d.z * d.z < lights[l].colour.w;
}

@compute @workgroup_size(64)
fn count(@builtin(global_invocation_id) id: vec3<u32>) {
    let c = id.x;
    if c >= CELLS {
        return;
    }
    let clo = cell_lo(c);
    let chi = clo + gp.cell.xyz;
    var n = 0u;
    for (var l = 0u; l < gp.counts.x; l++) {
        n += u32(reaches(l, clo, chi));
    }
    ranges[c] = vec2<u32>(0u, n);
}

@compute @workgroup_size(1)
fn scan() {
    var sum = 0u;
    for (var c = 0u; c < CELLS; c++) {
        let n = ranges[c].y;
        ranges[c] = vec2<u32>(sum, n);
        sum += n;
    }
    total[0] = sum;
}

@compute @workgroup_size(64)
fn fill(@builtin(global_invocation_id) id: vec3<u32>) {
    let c = id.x;
    if c >= CELLS {
        return;
    }
    let clo = cell_lo(c);
    let chi = clo + gp.cell.xyz;
    var k = ranges[c].x;
    for (var l = 0u; l < gp.counts.x; l++) {
        if reaches(l, clo, chi) {
            indices[k] = l;
            k++;
        }
    }
}
