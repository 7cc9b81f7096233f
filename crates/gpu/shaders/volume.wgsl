// Direct volume rendering: a transcription of crates/volume/src/dvr/, one
// invocation per pixel. The volume is the CPU marcher's prepared field (value and world
// gradient per voxel, crates/volume/src/march/) as an rgba32float 3D texture read with
// textureLoad and interpolated here, as the CPU does, so the two agree sample for sample (a
// hardware sampler would filter in 8-bit fixed-point weights); a sample reads 8 texels where
// central differences of the trilinear field would read 56.

struct Params {
    // xyz; w = half the view's height.
    eye: vec4<f32>,
    // xyz; w = 1 for parallel rays, 0 for a pinhole.
    forward: vec4<f32>,
    // xyz; w = the segment length in millimetres.
    right: vec4<f32>,
    // xyz; w = the opacity at which a ray stops.
    up: vec4<f32>,
    // World to grid index: the three columns of the linear part.
    to_index_x: vec4<f32>,
    to_index_y: vec4<f32>,
    to_index_z: vec4<f32>,
    // xyz = the world position of voxel (0, 0, 0); w = the gradient of full shading.
    origin: vec4<f32>,
    // xyz = towards the light; w = what a sample with no gradient keeps of its colour (1, or
    // the ambient weight as VTK's GPU caster).
    light: vec4<f32>,
    // ka, kd, ks, and 1 when samples are shaded.
    weights: vec4<f32>,
    background: vec4<f32>,
    // width, height, the transfer function's control points, geometry id.
    size: vec4<u32>,
    // nx, ny, nz, and the images drawn: one per highlight (one when unshaded).
    dims: vec4<u32>,
    // Bricks (4^3 cells each) along x, y, z.
    bricks: vec4<u32>,
    // The classification table's lowest value, entries per unit of value, last entry.
    classify: vec4<f32>,
}

// A lobe whose highlight an image shows, and (x) what it is scaled by: ks N(n), the
// normalisation's constant for that lobe.
struct Highlight {
    lobe: Lobe,
    scale: vec4<f32>,
}

// The module that includes this file defines MAX_HIGHLIGHTS, the most highlights one march
// draws (the host splits longer lists), and add_highlights for its images' lobes
// (wgsl::volume_module).

// A piece of the transfer function: (sigma, r, g, b) = at_start + slope * (value - start).
struct Piece {
    start: f32,
    at_start: vec4<f32>,
    slope: vec4<f32>,
}

@group(0) @binding(0) var<storage, read> params: Params;
// The transfer function classified as the CPU classifies it (Classification::tables).
@group(0) @binding(1) var<storage, read> pieces: array<Piece>;
@group(0) @binding(5) var<storage, read> first_piece: array<u32>;
@group(0) @binding(6) var<storage, read> bounds: array<f32>;
@group(0) @binding(2) var grid: texture_3d<f32>;
@group(0) @binding(3) var<storage, read_write> pixels: array<vec4<f32>>;
// Per brick, 0 where it holds a value with extinction, else how many bricks its empty
// surroundings reach (Classification::clearance).
@group(0) @binding(4) var<storage, read> clearance: array<u32>;
@group(0) @binding(7) var<storage, read> highlights: array<Highlight>;

// Where the ray grid_origin + grid_direction t leaves the cube of bricks within reach - 1
// bricks of the one holding cell (PreparedVolume::clear_exit_along, per axis).
fn clear_exit(cell: vec3<i32>, reach: i32, origin: vec3<f32>, inverse_direction: vec3<f32>) -> f32 {
    let brick = cell >> vec3<u32>(2u);
    let low = vec3<f32>((brick - vec3<i32>(reach - 1)) * 4);
    let high = vec3<f32>((brick + vec3<i32>(reach)) * 4);
    let exits = max((low - origin) * inverse_direction, (high - origin) * inverse_direction);
    return min(exits.x, min(exits.y, exits.z));
}

// Value (x) and world gradient (yzw) of a voxel.
fn voxel(i: i32, j: i32, k: i32) -> vec4<f32> {
    let high = vec3<i32>(params.dims.xyz) - vec3<i32>(1);
    let at = clamp(vec3<i32>(i, j, k), vec3<i32>(0), high);
    return textureLoad(grid, at, 0);
}

fn lerp(a: vec4<f32>, b: vec4<f32>, t: f32) -> vec4<f32> {
    return a + (b - a) * t;
}

fn last_index() -> vec3<f32> {
    return vec3<f32>(params.dims.xyz) - vec3<f32>(1.0);
}

// Value and world gradient at a grid index, trilinearly.
fn sample_at(index: vec3<f32>) -> vec4<f32> {
    let p = clamp(index, vec3<f32>(0.0), last_index());
    let base = floor(p);
    let f = p - base;
    let i = i32(base.x);
    let j = i32(base.y);
    let k = i32(base.z);
    let r00 = lerp(voxel(i, j, k), voxel(i + 1, j, k), f.x);
    let r10 = lerp(voxel(i, j + 1, k), voxel(i + 1, j + 1, k), f.x);
    let r01 = lerp(voxel(i, j, k + 1), voxel(i + 1, j, k + 1), f.x);
    let r11 = lerp(voxel(i, j + 1, k + 1), voxel(i + 1, j + 1, k + 1), f.x);
    return lerp(lerp(r00, r10, f.y), lerp(r01, r11, f.y), f.z);
}

fn to_index() -> mat3x3<f32> {
    return mat3x3<f32>(params.to_index_x.xyz, params.to_index_y.xyz, params.to_index_z.xyz);
}

// Extinction (w) and colour (xyz) at a value: the line of the piece of the transfer
// function it falls in, found by a table over the volume's range (Classification::at).
fn transfer(value: f32) -> vec4<f32> {
    let x = clamp((value - params.classify.x) * params.classify.y, 0.0, params.classify.z);
    let entry = first_piece[u32(x)];
    var piece = entry & 0x7fffu;
    if (entry & 0x8000u) != 0u {
        while piece < params.size.z && value > bounds[piece] {
            piece += 1u;
        }
    }
    let p = pieces[piece];
    let line = p.at_start + p.slope * (value - p.start);
    return vec4<f32>(line.yzw, line.x);
}

// A shaded sample: its colour without the highlight, the lobe's cosine there, and the
// highlight's weight (the gradient's strength; 0 where there is no gradient).
struct Shaded {
    colour: vec3<f32>,
    t: f32,
    weight: f32,
}

fn shade(g: vec3<f32>, base: vec3<f32>, wo: vec3<f32>) -> Shaded {
    let strength = length(g);
    if !(strength > 0.0) {
        return Shaded(base * params.light.w, 0.0, 0.0);
    }
    var normal = -g / strength;
    if dot(normal, wo) < 0.0 {
        normal = -normal;
    }
    let wi = params.light.xyz;
    let w = params.weights;
    let diffuse = max(dot(normal, wi), 0.0);
    let t = cos_lobe(params.size.w, normal, wo, wi);
    let lit = base * (w.x + w.y * diffuse);
    let weight = min(strength / params.origin.w, 1.0);
    return Shaded(base + (lit - base) * weight, t, weight);
}

fn pixel_jitter(x: u32, y: u32) -> f32 {
    var h = (x * 0x9E3779B9u) ^ (y * 0x85EBCA6Bu);
    h ^= h >> 15u;
    h *= 0x2C1B3C6Du;
    h ^= h >> 12u;
    return (f32(h >> 8u) + 1.0) / 16777216.0;
}

@compute @workgroup_size(8, 8)
fn march(@builtin(global_invocation_id) id: vec3<u32>) {
    let width = params.size.x;
    let height = params.size.y;
    if id.x >= width || id.y >= height {
        return;
    }
    let half_height = params.eye.w;
    let aspect = f32(width) / f32(height);
    let sx = ((f32(id.x) + 0.5) / f32(width) * 2.0 - 1.0) * aspect * half_height;
    let sy = (1.0 - (f32(id.y) + 0.5) / f32(height) * 2.0) * half_height;
    var origin = params.eye.xyz;
    var direction = params.forward.xyz;
    if params.forward.w > 0.5 {
        origin = origin + sx * params.right.xyz + sy * params.up.xyz;
    } else {
        direction = normalize(direction + sx * params.right.xyz + sy * params.up.xyz);
    }
    let wo = -direction;
    let grid_origin = to_index() * (origin - params.origin.xyz);
    let grid_direction = to_index() * direction;
    // The slab test: where the ray is inside [0, last index] on every axis.
    let high = last_index();
    var near = 0.0;
    var far = 3.0e38;
    var missed = false;
    for (var axis = 0; axis < 3; axis++) {
        let o = grid_origin[axis];
        let d = grid_direction[axis];
        if abs(d) < 1e-12 {
            if o < 0.0 || o > high[axis] {
                missed = true;
            }
            continue;
        }
        let a = (0.0 - o) / d;
        let b = (high[axis] - o) / d;
        near = max(near, min(a, b));
        far = min(far, max(a, b));
    }
    let index_of_pixel = id.y * width + id.x;
    let images = params.dims.w;
    let image_size = width * height;
    if missed || !(near < far) {
        for (var i = 0u; i < images; i++) {
            pixels[i * image_size + index_of_pixel] = vec4<f32>(params.background.xyz, 1.0);
        }
        return;
    }
    // Segment j > 0 ends at lattice + (j + 1) step, from j, so that a skip lands on the
    // lattice (crates/volume/src/march/ray/).
    let step = params.right.w;
    let first_end = near + step * pixel_jitter(id.x, id.y);
    let lattice = first_end - step;
    // A direction along a grid plane never leaves a brick across it.
    let inverse_direction = select(1.0 / grid_direction, vec3<f32>(1e30), abs(grid_direction) < vec3<f32>(1e-12));
    let last_cell = vec3<i32>(params.dims.xyz) - vec3<i32>(2);
    var colour = vec3<f32>(0.0);
    // Each image's highlights, summed apart from the colour they share.
    var highlighted = array<f32, MAX_HIGHLIGHTS>();
    let shaded_samples = params.weights.w > 0.5;
    var transmittance = 1.0;
    var t = near;
    var j = 0u;
    while t < far && 1.0 - transmittance < params.up.w {
        var next = first_end;
        if j > 0u {
            next = lattice + f32(j + 1u) * step;
        }
        let span = min(next, far) - t;
        let index = clamp(grid_origin + grid_direction * (t + 0.5 * span), vec3<f32>(0.0), high);
        t = next;
        j += 1u;
        let cell = min(vec3<i32>(floor(index)), last_cell);
        let brick = cell >> vec3<u32>(2u);
        let reach = clearance[u32(brick.x) + params.bricks.x * (u32(brick.y) + params.bricks.y * u32(brick.z))];
        if reach > 0u {
            // Every sample before the ray leaves the empty cube of bricks has no extinction
            // (a margin keeps the one rounding could place across the exit).
            let beyond = (clear_exit(cell, i32(reach), grid_origin, inverse_direction) - t) / step - 0.5 - 1e-3;
            if beyond > 0.0 {
                j += u32(ceil(beyond));
                t = lattice + f32(j) * step;
            }
            continue;
        }
        let field = sample_at(index);
        let medium = transfer(field.x);
        if medium.w <= 0.0 {
            continue;
        }
        let alpha = 1.0 - exp(-medium.w * span);
        if shaded_samples {
            let shaded = shade(field.yzw, medium.xyz, wo);
            colour += transmittance * alpha * shaded.colour;
            add_highlights(&highlighted, transmittance * alpha * shaded.weight, shaded.t);
        } else {
            colour += transmittance * alpha * medium.xyz;
        }
        transmittance *= 1.0 - alpha;
    }
    let behind = colour + transmittance * params.background.xyz;
    for (var i = 0u; i < images; i++) {
        pixels[i * image_size + index_of_pixel] = vec4<f32>(behind + vec3<f32>(highlighted[i]), 1.0);
    }
}
