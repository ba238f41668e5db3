//! The GPU renderer on lavapipe (CI) or any adapter: culling never changes
//! the picture, the GPU's surviving clusters equal the CPU reference of
//! the same test, the Z-prepass changes nothing, and the Cornell box is lit
//! by its ceiling light.
//!
//! Without an adapter the tests say so and pass, unless
//! `TOPOVOX_REQUIRE_GPU=1` (set by `.ci/run`).

use glam::Vec3;
use topovox::attributes::Appearance;
use topovox_testkit::shared_mesh;
use topovox_view::camera::{frustum_box, visible};
use topovox_view::hiz::Pyramid;
use topovox_view::{scenes, Camera, Culling, FrameOptions, Renderer, Scene};

fn renderer() -> Option<Renderer> {
    match Renderer::new() {
        Ok(r) => Some(r),
        Err(e) if std::env::var("TOPOVOX_REQUIRE_GPU").as_deref() == Ok("1") => panic!("TOPOVOX_REQUIRE_GPU=1 but {e}"),
        Err(e) => {
            eprintln!("skipping GPU test: {e}");
            None
        }
    }
}

fn cornell() -> Scene {
    let (mesh, app) = scenes::cornell();
    let mut s = Scene::default();
    assert_eq!(s.add_mesh(mesh.as_ref(), &app), 0);
    s
}

fn cameras(scene: &Scene) -> Vec<Camera> {
    let (lo, hi) = scene.bounds().unwrap();
    let c = (lo + hi) * 0.5;
    let e = (hi - lo).max_element();
    let cam = |eye: Vec3, target: Vec3, fov_deg| Camera { eye, target, up: Vec3::Y, fov_deg };
    vec![
        Camera::framing(lo, hi, 1),
        // Inside, looking at the back wall, and at a corner.
        cam(c + Vec3::new(0.0, 0.0, 0.2 * e), c - Vec3::new(0.0, 0.0, e), 60.0),
        cam(c, lo, 40.0),
        // Close to an occluder, narrow.
        cam(c + Vec3::new(0.1 * e, -0.2 * e, 0.4 * e), lo + (hi - lo) * Vec3::new(0.3, 0.3, 0.35), 25.0),
        // Far away, looking past the scene.
        cam(c + Vec3::new(3.0 * e, 0.0, 0.0), c + Vec3::new(3.0 * e, 0.0, 5.0 * e), 30.0),
    ]
}

fn frame(r: &Renderer, g: &topovox_view::GpuScene, camera: Camera, culling: Culling, prepass: bool) -> topovox_view::Frame {
    r.render(g, &FrameOptions { culling, prepass, read_hiz: true, ..FrameOptions::new(160, 120, camera) }).unwrap()
}

fn check_scene(r: &Renderer, scene: &Scene, what: &str) {
    let g = r.upload(scene).unwrap();
    assert!(g.clusters.len() > 1, "{what}: clusters");
    let (mut culled_somewhere, mut occluded_somewhere) = (false, false);
    for (n, cam) in cameras(scene).into_iter().enumerate() {
        // First, the two-pass variant, whose depth pass draws what the
        // previous camera's last frame drew (a stale set).
        let stale = frame(r, &g, cam, Culling::OcclusionTwoPass, n % 2 == 1);
        let none = frame(r, &g, cam, Culling::None, false);
        let frustum = frame(r, &g, cam, Culling::Frustum, false);
        assert_eq!(none.stats.clusters_after_frustum, none.stats.clusters, "{what}, camera {n}: nothing culled without culling");
        assert!(none.rgba == frustum.rgba, "{what}, camera {n}: frustum culling changed the picture");
        // The GPU's survivors are the CPU reference's.
        let (lo, hi) = g.bounds;
        let (near, far) = cam.depth_range(lo, hi);
        let m = cam.view_proj(160.0 / 120.0, near, far);
        let (flo, fhi) = frustum_box(m);
        let want: Vec<bool> = g.clusters.iter().map(|c| visible(c.lo, c.hi, &m, flo, fhi)).collect();
        assert_eq!(frustum.kept, want, "{what}, camera {n}: GPU and CPU frustum tests differ");
        let kept = want.iter().filter(|&&k| k).count() as u32;
        assert_eq!(frustum.stats.clusters_after_frustum, kept);
        let tris: u64 = g.clusters.iter().zip(&want).filter(|(_, k)| **k).map(|(c, _)| c.index_count as u64 / 3).sum();
        assert_eq!(frustum.stats.triangles_drawn, tris);
        culled_somewhere |= kept < g.clusters.len() as u32;
        // The Z-prepass changes nothing.
        let pre = frame(r, &g, cam, Culling::Frustum, true);
        assert!(pre.rgba == frustum.rgba, "{what}, camera {n}: the Z-prepass changed the picture");
        // Neither does occlusion culling, with or without the prepass, in one or two passes.
        for (culling, prepass) in
            [(Culling::Occlusion, false), (Culling::Occlusion, true), (Culling::OcclusionTwoPass, false), (Culling::OcclusionTwoPass, true)]
        {
            let occ = if culling == Culling::OcclusionTwoPass && prepass == (n % 2 == 1) {
                stale.clone()
            } else {
                frame(r, &g, cam, culling, prepass)
            };
            // The pyramid read back is the CPU's build of its own level 0.
            let hiz = occ.hiz.expect("asked for the pyramid");
            let [w0, _] = hiz.sizes[0];
            let level0: Vec<f32> = (0..120).flat_map(|y| hiz.levels[0][y * w0 as usize..y * w0 as usize + 160].to_vec()).collect();
            assert!(hiz.levels[0].iter().all(|d| (0.0..=1.0).contains(d)));
            assert_eq!(Pyramid::build(&level0, 160, 120), hiz, "{what}, camera {n}: GPU and CPU pyramids differ");
            // The GPU's survivors are the CPU test's on those levels.
            let want_occ: Vec<bool> = g.clusters.iter().zip(&want).map(|(c, &f)| f && !hiz.occluded(c.lo, c.hi, &m)).collect();
            assert_eq!(occ.kept, want_occ, "{what}, camera {n}: GPU and CPU occlusion tests differ");
            let after = want_occ.iter().filter(|&&k| k).count() as u32;
            assert_eq!(occ.stats.clusters_after_occlusion, Some(after));
            occluded_somewhere |= after < kept;
            assert!(occ.rgba == none.rgba, "{what}, camera {n}, {culling:?}, prepass {prepass}: occlusion culling changed the picture");
        }
    }
    assert!(culled_somewhere, "{what}: some camera culls some cluster");
    assert!(occluded_somewhere, "{what}: some camera culls some cluster by occlusion");
}

#[test]
fn culling_and_prepass_never_change_the_picture() {
    let Some(r) = renderer() else { return };
    check_scene(&r, &cornell(), "cornell");
    let mut bunny = Scene::default();
    bunny.add_mesh(shared_mesh("stanford-bunny.obj").as_ref(), &Appearance::default());
    check_scene(&r, &bunny, "bunny");
}

#[test]
fn the_cornell_box_is_lit_by_its_ceiling() {
    let Some(r) = renderer() else { return };
    let scene = cornell();
    let g = r.upload(&scene).unwrap();
    assert_eq!(g.lights.emissive_triangles, 2);
    assert!(g.lights.lights >= 1);
    let (lo, hi) = g.bounds;
    // From the open side, looking in.
    let cam = Camera { eye: Vec3::new(0.5, 0.5, 2.4), target: Vec3::new(0.5, 0.5, 0.0), up: Vec3::Y, fov_deg: 40.0 };
    assert!(lo.cmple(Vec3::ZERO).all() && hi.cmpge(Vec3::ONE).all());
    let mut o = FrameOptions { culling: Culling::Frustum, ..FrameOptions::new(200, 200, cam) };
    let f = r.render(&g, &o).unwrap();
    let px = |x: usize, y: usize| {
        let i = 4 * (y * 200 + x);
        [f.rgba[i], f.rgba[i + 1], f.rgba[i + 2]]
    };
    // The red wall on the left, the green on the right, the light at the top is the brightest.
    let left = px(40, 100);
    let right = px(160, 100);
    assert!(left[0] > left[1] + 40 && left[0] > left[2] + 40, "left wall {left:?}");
    assert!(right[1] > right[0] + 20 && right[1] > right[2] + 20, "right wall {right:?}");
    let light = px(100, 25);
    assert!(light.iter().all(|&c| c >= 250), "ceiling light {light:?}");
    // The light-grid view colours by list length: the cells near the lamp
    // list it (not blue), and the picture differs from the shaded one.
    o.light_grid_view = true;
    let grid = r.render(&g, &o).unwrap();
    assert!(grid.rgba != f.rgba);
    let i = 4 * (50 * 200 + 100);
    assert!(grid.rgba[i] > grid.rgba[i + 2], "a cell near the light is warm: {:?}", &grid.rgba[i..i + 3]);
    o.light_grid_view = false;
    assert!(r.render(&g, &o).unwrap().rgba == f.rgba);
    // Nearer the light is brighter: the back wall's top against its bottom.
    let (top, bottom) = (px(100, 50), px(100, 150));
    assert!(top[0] as u32 + top[1] as u32 > bottom[0] as u32 + bottom[1] as u32, "top {top:?} bottom {bottom:?}");
}

#[test]
fn the_city_is_large_lit_and_deterministic() {
    let (mesh, app) = scenes::city();
    assert!((900_000..1_200_000).contains(&mesh.triangles.len()), "{} triangles", mesh.triangles.len());
    let mut scene = Scene::default();
    assert_eq!(scene.add_mesh(mesh.as_ref(), &app), 0);
    let (lights, report) = topovox_view::lights::lights(&scene);
    assert!(report.lights >= 169 && lights.len() == report.lights, "one light per lamp at least: {report:?}");
    let partition = topovox_view::partition::Partition::new(&scene);
    assert!(partition.clusters.len() > 200);
    let (again, again_app) = scenes::city();
    assert!(again.positions == mesh.positions && again.triangles == mesh.triangles);
    assert_eq!(again_app.textures[0].rgba, app.textures[0].rgba);
    // Foliage cards: textured, cut out at 0.5, with texels both ways.
    let foliage = scene.materials.iter().filter(|m| m.cut_out()).count();
    assert_eq!(foliage, 1);
    let leaves = &app.textures[0].rgba;
    assert!(leaves.chunks_exact(4).any(|p| p[3] == 0) && leaves.chunks_exact(4).any(|p| p[3] == 255));
    assert_eq!(app.triangle_uv.len(), mesh.triangles.len());
    assert_eq!(app.triangle_uv.iter().filter(|uv| uv[0][0].is_finite()).count(), 600 * 3 * 2);
}

/// The GPU's light grid is the CPU build's, but for lights whose reach
/// meets a cell's box within rounding (a fused multiply–add on the GPU).
fn check_light_grid(r: &Renderer, scene: &Scene, what: &str) {
    use topovox_view::lights::{lights, reach_margin, LightGrid, GRID};
    let g = r.upload(scene).unwrap();
    let (ls, _) = lights(scene);
    let cpu = LightGrid::build(scene, &ls);
    assert_eq!((g.grid.lo, g.grid.cell, g.grid.unit), (cpu.lo, cpu.cell, cpu.unit));
    let mut differ = 0;
    for c in 0..GRID * GRID * GRID {
        let list = |grid: &LightGrid| {
            let [first, n] = grid.ranges[c];
            grid.indices[first as usize..(first + n) as usize].to_vec()
        };
        let (a, b) = (list(&g.grid), list(&cpu));
        if a != b {
            let clo = cpu.lo + cpu.cell * glam::Vec3::new((c % GRID) as f32, ((c / GRID) % GRID) as f32, (c / (GRID * GRID)) as f32);
            for l in a.iter().filter(|l| !b.contains(l)).chain(b.iter().filter(|l| !a.contains(l))) {
                let m = reach_margin(&ls[*l as usize], clo, clo + cpu.cell);
                assert!(m < 1e-5, "{what}: cell {c}, light {l}: GPU and CPU lists differ by more than rounding ({m})");
                differ += 1;
            }
        }
    }
    assert!(differ <= 8, "{what}: {differ} borderline differences");
    assert!(!cpu.indices.is_empty());
}

#[test]
fn the_light_grid_built_on_the_gpu_is_the_cpu_build() {
    let Some(r) = renderer() else { return };
    check_light_grid(&r, &cornell(), "cornell");
    let (mesh, app) = scenes::city();
    let mut city = Scene::default();
    city.add_mesh(mesh.as_ref(), &app);
    check_light_grid(&r, &city, "city");
}

fn srgb_byte(x: f32) -> f32 {
    let x = x.clamp(0.0, 1.0);
    255.0 * if x <= 0.003_130_8 { 12.92 * x } else { 1.055 * x.powf(1.0 / 2.4) - 0.055 }
}

#[test]
fn a_spray_point_is_lit_as_the_shader_documents() {
    let Some(r) = renderer() else { return };
    let scene = cornell();
    let mut g = r.upload(&scene).unwrap();
    // A point at the target, facing the eye: view Lambert term 1, view
    // attenuation 2 / (1³ + 1) = 1, so it shows emission + albedo × light.
    // With an odd picture its projection is the centre pixel's centre.
    let target = Vec3::new(0.5, 0.5, 0.5);
    let eye = target + Vec3::new(0.3, 0.4, 1.2);
    let p = topovox_view::spray::SprayPoint {
        position: target.to_array(),
        normal: (eye - target).normalize().to_array(),
        albedo: [0.5, 0.25, 0.1],
        light: [0.8, 0.6, 0.4],
        emission: [0.05, 0.0, 0.02],
        _pad: 0.0,
    };
    r.add_points(&mut g, &[p]).unwrap();
    let camera = Camera { eye, target, up: Vec3::Y, fov_deg: 40.0 };
    let o = FrameOptions { culling: Culling::None, mesh: false, ..FrameOptions::new(101, 81, camera) };
    let f = r.render(&g, &o).unwrap();
    assert_eq!(f.stats.points_drawn, 1);
    assert_eq!(f.stats.triangles_drawn, 0, "mesh off");
    let px = |x: usize, y: usize| &f.rgba[4 * (y * 101 + x)..4 * (y * 101 + x) + 3];
    for c in 0..3 {
        let want = srgb_byte(p.emission[c] + p.albedo[c] * p.light[c]);
        assert!((f32::from(px(50, 40)[c]) - want).abs() <= 1.0, "channel {c}: {:?} vs {want}", px(50, 40));
    }
    // Only that pixel is drawn (points are one pixel).
    let background = px(0, 0).to_vec();
    let drawn = (0..81).flat_map(|y| (0..101).map(move |x| (x, y))).filter(|&(x, y)| px(x, y) != background.as_slice()).count();
    assert_eq!(drawn, 1);
}

#[test]
fn culling_leaves_a_sprayed_cloud_unchanged() {
    let Some(r) = renderer() else { return };
    let scene = cornell();
    let tracer = topovox_view::spray::Tracer::new(&scene).unwrap();
    let (lo, hi) = scene.bounds().unwrap();
    let from_front = Camera { eye: Vec3::new(0.5, 0.5, 2.2), target: Vec3::new(0.5, 0.45, 0.0), up: Vec3::Y, fov_deg: 45.0 };
    let o = topovox_view::spray::SprayOptions { rays: 20_000, light_samples: 4, seed: 2, shadows: true };
    let points = tracer.spray_camera(&from_front, 1.0, &o);
    let mut g = r.upload(&scene).unwrap();
    r.add_points(&mut g, &points[..points.len() / 2]).unwrap();
    r.add_points(&mut g, &points[points.len() / 2..]).unwrap();
    for cam in [from_front, Camera::framing(lo, hi, 1)] {
        for mesh in [true, false] {
            let pictures: Vec<Vec<u8>> = [Culling::None, Culling::Frustum, Culling::Occlusion]
                .into_iter()
                .map(|culling| {
                    let o = FrameOptions { culling, mesh, ..FrameOptions::new(96, 96, cam) };
                    let f = r.render(&g, &o).unwrap();
                    assert_eq!(f.stats.points_drawn, points.len() as u64);
                    f.rgba
                })
                .collect();
            assert!(pictures.windows(2).all(|w| w[0] == w[1]), "mesh {mesh}: culling changed the picture");
        }
    }
    // Points added in two parts draw as when added at once.
    let mut once = r.upload(&scene).unwrap();
    r.add_points(&mut once, &points).unwrap();
    let o = FrameOptions { culling: Culling::None, mesh: false, ..FrameOptions::new(96, 96, from_front) };
    assert_eq!(r.render(&once, &o).unwrap().rgba, r.render(&g, &o).unwrap().rgba);
    r.clear_points(&mut once);
    assert_eq!(r.render(&once, &o).unwrap().stats.points_drawn, 0);
}

fn cut_out_scene() -> Scene {
    let (mesh, app) = scenes::cut_outs();
    let mut s = Scene::default();
    assert_eq!(s.add_mesh(mesh.as_ref(), &app), 0);
    s
}

#[test]
fn alpha_cut_outs_show_what_is_behind_with_any_culling_and_prepass() {
    let Some(r) = renderer() else { return };
    let scene = cut_out_scene();
    let g = r.upload(&scene).unwrap();
    assert_eq!(g.clusters.len(), 6, "each triangle is a cluster: the back ones apart from the front ones");
    // Straight on, the front quad filling a 128² picture: with a 60° field
    // of view from z = 0.5 + d, d = 0.5 / tan 30°.
    let d = 0.5 / 30f32.to_radians().tan();
    let camera = Camera { eye: Vec3::new(0.5, 0.5, 0.5 + d), target: Vec3::new(0.5, 0.5, 0.0), up: Vec3::Y, fov_deg: 60.0 };
    let mut pictures = Vec::new();
    for culling in [Culling::None, Culling::Frustum, Culling::Occlusion, Culling::OcclusionTwoPass] {
        for prepass in [false, true] {
            let o = FrameOptions { culling, prepass, gamma: false, ..FrameOptions::new(128, 128, camera) };
            let f = r.render(&g, &o).unwrap();
            // The back quad lies wholly behind the front one: only a depth
            // pass that cuts out like the shading keeps it.
            assert!(f.kept.iter().all(|&k| k), "{culling:?}: a quad behind the cut-outs was culled");
            pictures.push(f.rgba);
        }
    }
    assert!(pictures.windows(2).all(|w| w[0] == w[1]), "culling or the prepass changed a cut-out picture");
    // Cell (i, j) of the checker, i across and j down from the top: its
    // centre pixel is blue where the texel is opaque, red where cut out.
    let f = &pictures[0];
    for j in 0..8 {
        for i in 0..8 {
            let (x, y) = (16 * i + 8, 16 * j + 8);
            let p = &f[4 * (y * 128 + x)..4 * (y * 128 + x) + 3];
            let opaque = (i + j) % 2 == 0;
            // The green quad (0.2..0.8 at z = 0.25) covers cells 2..=5 of
            // the front quad's; the head-light's specular term adds white.
            let dominant = if opaque {
                2
            } else if (2..=5).contains(&i) && (2..=5).contains(&j) {
                1
            } else {
                0
            };
            let others = (0..3).filter(|&c| c != dominant).map(|c| u32::from(p[c])).max().unwrap();
            assert!(u32::from(p[dominant]) > 2 * others + 60, "cell ({i}, {j}) should show channel {dominant}: {p:?}");
        }
    }
}

#[test]
fn the_cluster_boxes_show_kept_and_culled_clusters() {
    let Some(r) = renderer() else { return };
    let scene = cornell();
    let g = r.upload(&scene).unwrap();
    // Close to an occluder and narrow: some clusters culled, some kept.
    let (lo, hi) = scene.bounds().unwrap();
    let camera = cameras(&scene)[3];
    let o = |culling, boxes| FrameOptions { culling, boxes, ..FrameOptions::new(160, 120, camera) };
    let plain = r.render(&g, &o(Culling::Occlusion, false)).unwrap();
    let boxed = r.render(&g, &o(Culling::Occlusion, true)).unwrap();
    assert!(plain.kept.iter().any(|&k| k) && plain.kept.iter().any(|&k| !k), "the camera culls some clusters ({lo}..{hi})");
    assert_eq!(plain.kept, boxed.kept, "drawing boxes changes no culling");
    let count = |f: &topovox_view::Frame, rgb: [u8; 3]| f.rgba.chunks_exact(4).filter(|p| p[..3] == rgb).count();
    // The boxes' colours, written as they are: (0.2, 1, 0.4) and (1, 0.2, 0.2).
    let (green, red) = ([51, 255, 102], [255, 51, 51]);
    assert_eq!((count(&plain, green), count(&plain, red)), (0, 0));
    assert!(count(&boxed, green) > 0 && count(&boxed, red) > 0, "kept and culled boxes drawn");
    // Without culling every box is green.
    let all = r.render(&g, &o(Culling::None, true)).unwrap();
    assert!(count(&all, green) > 0 && count(&all, red) == 0);
    // Everything that is not a box line is the plain picture.
    let differ = plain.rgba.chunks_exact(4).zip(boxed.rgba.chunks_exact(4)).filter(|(a, b)| a != b).count();
    assert_eq!(differ, count(&boxed, green) + count(&boxed, red) - count(&plain, green) - count(&plain, red));
}

#[test]
fn a_voxel_grid_drawn_by_the_gpu_covers_the_pixels_the_cpu_ray_caster_does() {
    // The CPU ray caster (topovox::render::raycast) is orthographic and
    // frames the grid's bounding sphere (radius r, 2% margin); the GPU
    // camera is perspective, so it looks from 1000 r away with the field of
    // view that shows the same ±1.02 r: the picture scale then varies by at
    // most 0.1% over the grid's depth, well under a pixel at 128². Both
    // sample at pixel centres (a voxel face covers a pixel when its centre
    // is inside, on the GPU by the rasterization rule), so the silhouettes
    // agree except where a pixel centre lies on a face's edge within
    // rounding: every disagreement must be a silhouette pixel (a 4-neighbour
    // classified otherwise by the CPU) and they must be under 2% of those.
    let Some(r) = renderer() else { return };
    let mesh = shared_mesh("stanford-bunny.obj");
    let grid = topovox::GridSpec::from_resolution(&mesh.as_ref().bounds(), 32).unwrap();
    let (bits, _) = topovox::voxelize::fast(topovox::voxelize::Mode::Cover, mesh.as_ref(), &grid, &Default::default());
    let mut scene = Scene::default();
    let m = scene.add_material(topovox_view::scene::ShadeMaterial::new([0.7; 3], [0.0; 3], 0.7));
    scene.add_quads(&topovox::export::greedy::greedy_quads(&bits.to_dense()), Vec3::ZERO, Vec3::ONE, m);
    let g = r.upload(&scene).unwrap();
    let d = bits.dims();
    let size = glam::DVec3::new(d[0] as f64, d[1] as f64, d[2] as f64);
    let radius = 0.5 * size.length();
    let (w, h) = (128u32, 128u32);
    use topovox::render::raycast::{render, RenderOptions, View};
    for (view, towards) in [
        (View::Axis(0), glam::DVec3::X),
        (View::Axis(2), glam::DVec3::Z),
        (View::Angles(30.0, 20.0), {
            // Azimuth 30° from the front axis (z, after up y) towards the side axis (x), raised 20°.
            let (az, el) = (30f64.to_radians(), 20f64.to_radians());
            (glam::DVec3::Z * az.cos() + glam::DVec3::X * az.sin()) * el.cos() + glam::DVec3::Y * el.sin()
        }),
    ] {
        let cpu = render(&bits, &RenderOptions { width: w, height: h, view, up: 1, ..Default::default() });
        let dist = 1000.0 * radius;
        let centre = size * 0.5;
        let camera = Camera {
            eye: (centre + towards.normalize() * dist).as_vec3(),
            target: centre.as_vec3(),
            up: Vec3::Y,
            fov_deg: (2.0 * (1.02 * radius / dist).atan()).to_degrees() as f32,
        };
        let o = FrameOptions::new(w, h, camera);
        let gpu = r.render(&g, &o).unwrap();
        let (cbg, gbg) = (&cpu.rgb[..3], &gpu.rgba[..3]);
        let on_cpu = |x: i64, y: i64| {
            let i = 3 * (y as usize * w as usize + x as usize);
            &cpu.rgb[i..i + 3] != cbg
        };
        let (mut differ, mut edges, mut covered) = (0, 0, 0);
        for y in 0..h as i64 {
            for x in 0..w as i64 {
                let i = 4 * (y as usize * w as usize + x as usize);
                let on_gpu = &gpu.rgba[i..i + 3] != gbg;
                let c = on_cpu(x, y);
                covered += usize::from(c);
                let edge = [(-1, 0), (1, 0), (0, -1), (0, 1)]
                    .iter()
                    .any(|&(dx, dy)| (0..w as i64).contains(&(x + dx)) && (0..h as i64).contains(&(y + dy)) && on_cpu(x + dx, y + dy) != c);
                edges += usize::from(edge);
                if on_gpu != c {
                    differ += 1;
                    assert!(edge, "{view:?}: pixel ({x}, {y}) differs away from the silhouette (cpu {c}, gpu {on_gpu})");
                }
            }
        }
        assert_eq!(covered as u64, cpu.covered, "{view:?}: the CPU's own count");
        assert!(covered > 2000, "{view:?}: the bunny fills the picture: {covered}");
        eprintln!("{view:?}: {differ} of {edges} silhouette pixels differ, {covered} covered");
        assert!(differ * 50 <= edges, "{view:?}: {differ} of {edges} silhouette pixels differ");
    }
}

#[test]
fn the_overlay_draws_font8x8_glyphs_and_nothing_else() {
    let Some(r) = renderer() else { return };
    let scene = cornell();
    let mut g = r.upload(&scene).unwrap();
    let (lo, hi) = scene.bounds().unwrap();
    let o = FrameOptions::new(96, 64, Camera::framing(lo, hi, 1));
    let plain = r.render(&g, &o).unwrap();
    r.set_overlay(&mut g, &["A7".to_string(), "x".to_string()]);
    let text = r.render(&g, &o).unwrap();
    let px = |f: &topovox_view::Frame, x: usize, y: usize| f.rgba[4 * (y * 96 + x)..4 * (y * 96 + x) + 3].to_vec();
    // Glyph k of line l: its texel (tx, ty) covers pixels 4 + 16 k + 2 tx
    // (+1) across and 4 + 18 l + 2 ty (+1) down.
    let mut glyph_pixels = std::collections::HashSet::new();
    for (l, line) in ["A7", "x"].iter().enumerate() {
        for (k, c) in line.chars().enumerate() {
            let rows = font8x8::legacy::BASIC_LEGACY[c as usize];
            for (ty, row) in rows.iter().enumerate() {
                for tx in 0..8 {
                    let on = row & (1 << tx) != 0;
                    for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                        let (x, y) = (4 + 16 * k + 2 * tx + dx, 4 + 18 * l + 2 * ty + dy);
                        glyph_pixels.insert((x, y));
                        let want = if on { vec![255, 255, 255] } else { vec![13, 13, 15] };
                        assert_eq!(px(&text, x, y), want, "{c:?} texel ({tx}, {ty})");
                    }
                }
            }
        }
    }
    for y in 0..64 {
        for x in 0..96 {
            if !glyph_pixels.contains(&(x, y)) {
                assert_eq!(px(&text, x, y), px(&plain, x, y), "({x}, {y}) is not under the text");
            }
        }
    }
    r.set_overlay(&mut g, &[]);
    assert_eq!(r.render(&g, &o).unwrap().rgba, plain.rgba);
}
