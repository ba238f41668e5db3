//! The ray spray (CPU): points lie on the surface, face the ray, come out
//! the same for any thread count, shadow rays only remove light, the light
//! term converges to the integral it estimates, and the PLY round-trips.

use glam::Vec3;
use topovox_io::spray_cloud::{read_ply, write_ply, SprayPoint};
use topovox_view::spray::{SprayOptions, Tracer};
use topovox_view::{scenes, Camera, Scene};

fn cornell() -> Scene {
    let (mesh, app) = scenes::cornell();
    let mut s = Scene::default();
    assert_eq!(s.add_mesh(mesh.as_ref(), &app), 0);
    s
}

/// Distance from `p` to triangle `t` (closest point by regions, Ericson,
/// Real-Time Collision Detection §5.1.5), in f64.
fn dist_to_triangle(p: Vec3, t: [Vec3; 3]) -> f64 {
    let [a, b, c, p] = [t[0], t[1], t[2], p].map(|v| v.as_dvec3());
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    let closest = if d1 <= 0.0 && d2 <= 0.0 {
        a
    } else {
        let bp = p - b;
        let (d3, d4) = (ab.dot(bp), ac.dot(bp));
        let cp = p - c;
        let (d5, d6) = (ab.dot(cp), ac.dot(cp));
        let (vc, vb, va) = (d1 * d4 - d3 * d2, d5 * d2 - d1 * d6, d3 * d6 - d5 * d4);
        if d3 >= 0.0 && d4 <= d3 {
            b
        } else if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
            a + ab * (d1 / (d1 - d3))
        } else if d6 >= 0.0 && d5 <= d6 {
            c
        } else if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
            a + ac * (d2 / (d2 - d6))
        } else if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
            b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)))
        } else {
            let denom = 1.0 / (va + vb + vc);
            a + ab * (vb * denom) + ac * (vc * denom)
        }
    };
    (p - closest).length()
}

fn triangles(scene: &Scene) -> Vec<[Vec3; 3]> {
    scene.vertices.chunks_exact(3).map(|t| [0, 1, 2].map(|c| Vec3::from(t[c].position))).collect()
}

fn pool(n: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new().num_threads(n).build().unwrap()
}

#[test]
fn points_lie_on_the_surface_and_face_the_ray() {
    let scene = cornell();
    let tracer = Tracer::new(&scene).unwrap();
    assert_eq!(tracer.emissive_triangles(), 2);
    let (lo, hi) = scene.bounds().unwrap();
    let cams = [
        Camera::framing(lo, hi, 1),
        Camera { eye: Vec3::new(0.5, 0.5, 0.9), target: Vec3::new(0.2, 0.1, 0.0), up: Vec3::Y, fov_deg: 70.0 },
    ];
    let tris = triangles(&scene);
    // f32 hit points: a few ulps of the box's size.
    let eps = 1e-5 * f64::from((hi - lo).max_element());
    for cam in cams {
        let o = SprayOptions { rays: 5000, light_samples: 4, seed: 7, shadows: true };
        let points = tracer.spray_camera(&cam, 4.0 / 3.0, &o);
        assert!(points.len() > 1000, "most rays of a camera looking at the box hit it: {}", points.len());
        for p in &points {
            let q = Vec3::from(p.position);
            let d = tris.iter().map(|&t| dist_to_triangle(q, t)).fold(f64::INFINITY, f64::min);
            assert!(d <= eps, "point {q} is {d} from the mesh (epsilon {eps})");
            assert!(Vec3::from(p.normal).dot(cam.eye - q) >= 0.0, "normal faces the eye");
            assert!((Vec3::from(p.normal).length() - 1.0).abs() < 1e-5);
            assert!(p.light.iter().chain(&p.albedo).chain(&p.emission).all(|v| v.is_finite() && *v >= 0.0));
        }
        // Some points see the lamp, some lie in shadow or face away.
        assert!(points.iter().any(|p| p.light[0] > 0.0));
        assert!(points.iter().any(|p| p.light[0] == 0.0));
    }
}

#[test]
fn the_cloud_does_not_depend_on_the_thread_count() {
    let scene = cornell();
    let tracer = Tracer::new(&scene).unwrap();
    let (lo, hi) = scene.bounds().unwrap();
    let cam = Camera::framing(lo, hi, 1);
    let o = SprayOptions { rays: 3 * topovox_view::spray::BLOCK + 17, light_samples: 3, seed: 11, shadows: true };
    let one = pool(1).install(|| tracer.spray_camera(&cam, 1.5, &o));
    let two = pool(2).install(|| tracer.spray_camera(&cam, 1.5, &o));
    assert_eq!(one, two);
    let other = pool(2).install(|| tracer.spray_camera(&cam, 1.5, &SprayOptions { seed: 12, ..o }));
    assert_ne!(one, other, "another seed, other rays");
    let cone = |n| pool(n).install(|| tracer.spray_cone(cam.eye, cam.target - cam.eye, 0.1, &o));
    assert_eq!(cone(1), cone(2));
}

#[test]
fn shadow_rays_only_take_light_away() {
    let scene = cornell();
    let tracer = Tracer::new(&scene).unwrap();
    let (lo, hi) = scene.bounds().unwrap();
    let cam = Camera::framing(lo, hi, 1);
    let o = SprayOptions { rays: 4000, light_samples: 8, seed: 3, shadows: true };
    let lit = tracer.spray_camera(&cam, 1.0, &o);
    let open = tracer.spray_camera(&cam, 1.0, &SprayOptions { shadows: false, ..o });
    assert_eq!(lit.len(), open.len());
    let mut darker = 0;
    for (a, b) in lit.iter().zip(&open) {
        assert_eq!(a.position, b.position, "same rays, same samples");
        for c in 0..3 {
            assert!(a.light[c] <= b.light[c] * (1.0 + 1e-6));
        }
        darker += usize::from(a.light[0] < b.light[0]);
    }
    assert!(darker > 50, "the blocks cast shadows on the floor: {darker} points darker");
}

#[test]
fn the_light_term_estimates_its_integral() {
    // A floor point below the lamp, the blocks out of the way (no shadow
    // rays): the light term's mean over many samples against a midpoint
    // sum of the same integrand over the lamp's quad.
    let scene = cornell();
    let tracer = Tracer::new(&scene).unwrap();
    let o = SprayOptions { rays: 1, light_samples: 200_000, seed: 5, shadows: false };
    // Off the floor quad's diagonal: obvhs's Möller–Trumbore test is not
    // watertight on shared edges (a set of rays of measure zero).
    let origin = Vec3::new(0.5, 0.5, 0.5);
    let mut rng = <rand_chacha::ChaCha8Rng as rand::SeedableRng>::seed_from_u64(1);
    let p = tracer.point(origin, -Vec3::Y, &o, &mut rng).unwrap();
    assert!((Vec3::from(p.position) - Vec3::new(0.5, 0.0, 0.5)).length() < 1e-6);
    assert_eq!(p.normal, [0.0, 1.0, 0.0]);
    // The lamp: 0.38..0.62 in x and z at y = 0.998, emission 12; one unit
    // is 1/8 (the box's extent over 8).
    let unit = 1.0 / 8.0f64;
    let (side, n) = (0.24f64, 400);
    let area_units = side * side / (unit * unit);
    let mut sum = 0.0;
    for i in 0..n {
        for k in 0..n {
            let q = glam::DVec3::new(0.38 + side * (i as f64 + 0.5) / n as f64, 0.998, 0.38 + side * (k as f64 + 0.5) / n as f64);
            let to = q - glam::DVec3::new(0.5, 0.0, 0.5);
            let d = to.length();
            let du = d / unit;
            sum += (to.y / d) / (du * du * du + 1.0);
        }
    }
    // The lamp is one light or one per triangle, as crate::lights merges
    // it: each light of area a gives √a times its mean, ∫/√a, and both
    // halves have the same area.
    let lights = topovox_view::lights::lights(&scene).1.lights;
    assert!(lights == 1 || lights == 2, "{lights}");
    let light_area = area_units / lights as f64;
    let expected = 12.0 * (area_units * sum / (n * n) as f64) / light_area.sqrt();
    let got = f64::from(p.light[0]);
    assert!((got - expected).abs() < 0.01 * expected, "light term {got}, integral {expected}");
    assert_eq!(p.light[0], p.light[1]);
}

#[test]
fn a_scene_without_lamps_gets_no_light_and_misses_are_dropped() {
    let mut scene = Scene::default();
    let m = scene.add_material(topovox_view::scene::ShadeMaterial::new([0.5; 3], [0.0; 3], 0.5));
    assert!(scene.push_triangle([Vec3::ZERO, Vec3::X, Vec3::Y], m));
    let tracer = Tracer::new(&scene).unwrap();
    assert_eq!(tracer.emissive_triangles(), 0);
    let cam = Camera { eye: Vec3::new(0.25, 0.25, 2.0), target: Vec3::new(0.25, 0.25, 0.0), up: Vec3::Y, fov_deg: 60.0 };
    let o = SprayOptions { rays: 2000, light_samples: 4, seed: 1, shadows: true };
    let points = tracer.spray_camera(&cam, 1.0, &o);
    assert!(!points.is_empty() && points.len() < 2000, "some rays miss the triangle: {}", points.len());
    assert!(points.iter().all(|p| p.light == [0.0; 3] && p.position[2].abs() < 1e-6));
    assert!(Tracer::new(&Scene::default()).is_err());
}

#[test]
fn the_ply_round_trips_and_refuses_other_clouds() {
    let scene = cornell();
    let tracer = Tracer::new(&scene).unwrap();
    let (lo, hi) = scene.bounds().unwrap();
    let points = tracer.spray_camera(&Camera::framing(lo, hi, 1), 1.0, &SprayOptions { rays: 500, ..Default::default() });
    let mut bytes = Vec::new();
    write_ply(&mut bytes, &points).unwrap();
    assert_eq!(read_ply(&bytes).unwrap(), points);
    let mut empty = Vec::new();
    write_ply(&mut empty, &[]).unwrap();
    assert_eq!(read_ply(&empty).unwrap(), Vec::<SprayPoint>::new());
    let plain = b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n";
    let e = read_ply(plain).unwrap_err();
    assert!(e.contains("no property nx"), "{e}");
    assert!(read_ply(b"not a ply").is_err());
}

#[test]
fn axis_aligned_rays_hit() {
    // Directions with negative zeros (−Y is (−0, −1, −0)) once missed
    // everything inside obvhs's traversal.
    let tracer = Tracer::new(&cornell()).unwrap();
    let c = Vec3::new(0.5, 0.55, 0.9);
    for (dir, t) in [(-Vec3::X, 0.5), (Vec3::X, 0.5), (-Vec3::Y, 0.55), (Vec3::Y, 0.45), (-Vec3::Z, 0.9)] {
        let (got, _) = tracer.hit(c, dir).unwrap_or_else(|| panic!("{dir} missed"));
        assert!((got - t).abs() < 1e-5, "{dir}: {got} != {t}");
    }
    assert_eq!(tracer.hit(c, Vec3::Z), None, "the box is open towards +z");
}

#[test]
fn a_cursor_ray_passes_through_what_the_cursor_shows() {
    // The viewer sprays along Camera::ray through the cursor's normalised
    // coordinates: that ray must pass through the world point the renderer
    // projects to those coordinates.
    let cam = Camera { eye: Vec3::new(1.0, 2.0, 3.0), target: Vec3::new(-0.5, 0.2, 0.1), up: Vec3::Y, fov_deg: 50.0 };
    let aspect = 1.6;
    let vp = cam.view_proj(aspect, 0.1, 100.0);
    let mut rng = <rand_chacha::ChaCha8Rng as rand::SeedableRng>::seed_from_u64(9);
    for _ in 0..200 {
        let p = cam.target + Vec3::new(rand::Rng::random_range(&mut rng, -1.0..1.0), rand::Rng::random_range(&mut rng, -1.0..1.0), 0.3);
        let c = vp * p.extend(1.0);
        let (x, y) = (c.x / c.w, c.y / c.w);
        let along = cam.ray(aspect, x, y);
        let to = (p - cam.eye).normalize();
        assert!(along.cross(to).length() < 1e-5, "ray {along} misses {p} ({to})");
    }
    assert!((cam.ray(aspect, 0.0, 0.0) - (cam.target - cam.eye).normalize()).length() < 1e-6);
}

#[test]
fn rays_pass_through_cut_outs_and_take_the_texture_colour() {
    let (mesh, app) = scenes::cut_outs();
    let mut scene = Scene::default();
    assert_eq!(scene.add_mesh(mesh.as_ref(), &app), 0);
    let tracer = Tracer::new(&scene).unwrap();
    // Straight on, the front quad just filling the view (24° at 2.5 away).
    let cam = Camera { eye: Vec3::new(0.5, 0.5, 3.0), target: Vec3::new(0.5, 0.5, 0.0), up: Vec3::Y, fov_deg: 24.0 };
    let points = tracer.spray_camera(&cam, 1.0, &SprayOptions { rays: 20_000, light_samples: 0, seed: 4, shadows: false });
    let mut seen = [0usize; 3];
    for p in &points {
        let q = Vec3::from(p.position);
        // Where the ray crosses z = 0.5, the checker texel it meets.
        let at = cam.eye + (q - cam.eye) * ((0.5 - cam.eye.z) / (q.z - cam.eye.z));
        let (u, v) = (at.x, 1.0 - at.y);
        if !(0.0..1.0).contains(&u) || !(0.0..1.0).contains(&v) {
            continue;
        }
        let (i, j) = ((u * 8.0) as usize, (v * 8.0) as usize);
        // Texels near an edge are left out: f32 rounding may pick either.
        let frac = |x: f32| (x * 8.0).fract();
        if [frac(u), frac(v)].iter().any(|f| !(0.01..0.99).contains(f)) {
            continue;
        }
        let opaque = (i + j) % 2 == 0;
        if opaque {
            assert!((q.z - 0.5).abs() < 1e-5, "texel ({i}, {j}) is opaque: the ray stops on the front quad, not at {q}");
            assert_eq!(p.albedo, [0.0, 0.0, 1.0], "the texture's blue");
            seen[0] += 1;
        } else {
            assert!(q.z < 0.5 - 1e-3, "texel ({i}, {j}) is cut out: the ray goes through, not stopping at {q}");
            let green = q.z > 0.2;
            assert_eq!(p.albedo, if green { [0.0, 1.0, 0.0] } else { [1.0, 0.0, 0.0] });
            seen[1 + usize::from(green)] += 1;
        }
    }
    assert!(seen.iter().all(|&n| n > 100), "front, red and green all hit: {seen:?}");
}

/// A cloud written before the rename (`comment voxkit spray`, 100 rays at
/// the bundled box) still opens: the reader keys on the properties, not
/// the comment.
#[test]
fn spray_cloud_written_as_voxkit_still_reads() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/voxkit-spray.ply");
    let bytes = std::fs::read(path).unwrap();
    assert!(bytes.windows(20).any(|w| w == b"comment voxkit spray"), "the fixture is an old file");
    let points = read_ply(&bytes).unwrap();
    assert_eq!(points.len(), 21);
    assert!(points.iter().all(|p| (Vec3::from(p.normal).length() - 1.0).abs() < 1e-3));
}
