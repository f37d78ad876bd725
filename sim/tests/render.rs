//! The headless renderer on known scenes: colours at projected centres, depth order where
//! objects overlap, background elsewhere, image size and PNG format — on every backend
//! this machine has (Vulkan/lavapipe, GL/llvmpipe), and the error when there is none.

use image::{Rgba, RgbaImage};
use nalgebra::{Isometry3, Point3};
use nbv_sim::render::{
    Backends, Camera, Color, LineSet, MeshItem, PointSet, RenderError, RenderScene, Renderer,
    RendererOptions, VoxelSet, save_png, tessellate,
};
use std::sync::OnceLock;

const W: u32 = 1280;
const H: u32 = 960;
const RED: Color = Color::rgb(0.85, 0.10, 0.10);
const BLUE: Color = Color::rgb(0.10, 0.25, 0.85);

/// One renderer for the whole test binary (device creation is the slow part).
fn renderer() -> &'static Renderer {
    static R: OnceLock<Renderer> = OnceLock::new();
    R.get_or_init(|| match Renderer::new() {
        Ok(r) => r,
        Err(e) => panic!("the renderer tests need a GPU or Mesa's software drivers: {e}"),
    })
}

fn pixel_at(img: &RgbaImage, p: nalgebra::Point2<f64>) -> [u8; 4] {
    let (x, y) = (p.x.floor() as u32, p.y.floor() as u32);
    assert!(
        x < img.width() && y < img.height(),
        "({x}, {y}) outside the image"
    );
    img.get_pixel(x, y).0
}

fn is_red(c: [u8; 4]) -> bool {
    let [r, g, b, _] = c.map(i32::from);
    r > 90 && r > g + 60 && r > b + 60
}

fn is_blue(c: [u8; 4]) -> bool {
    let [r, g, b, _] = c.map(i32::from);
    b > 90 && b > r + 60 && b > g + 30
}

fn is_background(c: [u8; 4]) -> bool {
    let want = Color::BACKGROUND.to_srgb8();
    c.iter()
        .zip(want)
        .all(|(&a, b)| (i32::from(a) - i32::from(b)).abs() <= 1)
}

/// Looking along +x from (0, 0, 0.5): a box of colour `near_color` at x = 1.0 slightly to
/// the right, and one of `far_color` at x = 1.5 to the left; in the image the near box
/// covers part of the far one.
fn two_boxes(near_color: Color, far_color: Color) -> (RenderScene, Camera) {
    let mut scene = RenderScene::new();
    // The far box first, so that drawing order cannot explain the result.
    scene.add_mesh(MeshItem::flat(
        tessellate::cuboid([0.2, 0.2, 0.2]),
        Isometry3::translation(1.5, 0.15, 0.5),
        far_color,
    ));
    scene.add_mesh(MeshItem::flat(
        tessellate::cuboid([0.2, 0.2, 0.2]),
        Isometry3::translation(1.0, -0.05, 0.5),
        near_color,
    ));
    let camera = Camera::look_at(Point3::new(0.0, 0.0, 0.5), Point3::new(2.0, 0.0, 0.5));
    (scene, camera)
}

/// A point on the far box's front face (x = 1.4) seen at 0.045 rad to the left, where the
/// near box (front face x = 0.9, y ≤ 0.05) is in front of it.
fn overlap_point() -> Point3<f64> {
    Point3::new(1.4, 1.4 * 0.045f64.tan(), 0.5)
}

fn check_two_boxes(
    img: &RgbaImage,
    camera: &Camera,
    near_ok: fn([u8; 4]) -> bool,
    far_ok: fn([u8; 4]) -> bool,
) {
    assert_eq!(img.dimensions(), (W, H));
    let near_c = camera.project(&Point3::new(1.0, -0.05, 0.5), W, H).unwrap();
    let far_c = camera.project(&Point3::new(1.5, 0.15, 0.5), W, H).unwrap();
    assert!(
        near_ok(pixel_at(img, near_c)),
        "near box centre {:?}",
        pixel_at(img, near_c)
    );
    assert!(
        far_ok(pixel_at(img, far_c)),
        "far box centre {:?}",
        pixel_at(img, far_c)
    );
    // The overlap lies inside both silhouettes; the near box must win there.
    let o = camera.project(&overlap_point(), W, H).unwrap();
    let on_near_face = camera
        .project(&Point3::new(0.9, 0.9 * 0.045f64.tan(), 0.5), W, H)
        .unwrap();
    assert!((o - on_near_face).norm() < 1e-6);
    assert!(near_ok(pixel_at(img, o)), "overlap {:?}", pixel_at(img, o));
    // Corners and a pixel well above both boxes are background.
    for (x, y) in [(0, 0), (W - 1, 0), (0, H - 1), (W - 1, H - 1)] {
        assert!(is_background(img.get_pixel(x, y).0), "corner ({x}, {y})");
    }
    let above = camera.project(&Point3::new(1.5, 0.15, 0.9), W, H).unwrap();
    assert!(is_background(pixel_at(img, above)));
}

#[test]
fn boxes_show_their_colours_and_the_nearer_one_hides_the_farther() {
    let r = renderer();
    let (scene, camera) = two_boxes(BLUE, RED);
    let img = r.render(&scene, &camera, W, H).unwrap();
    check_two_boxes(&img, &camera, is_blue, is_red);
    // Swap the colours: the same pixels change colour, so neither depth nor colour is luck.
    let (scene, camera) = two_boxes(RED, BLUE);
    let img = r.render(&scene, &camera, W, H).unwrap();
    check_two_boxes(&img, &camera, is_red, is_blue);
}

#[test]
fn box_faces_are_lit_differently_and_antialiased() {
    // A box seen from above a corner: three faces, three brightnesses.
    let mut scene = RenderScene::new();
    scene.add_mesh(MeshItem::flat(
        tessellate::cuboid([0.4, 0.4, 0.4]),
        Isometry3::identity(),
        Color::rgb(0.7, 0.7, 0.7),
    ));
    let camera = Camera::look_at(Point3::new(-1.5, -1.2, 1.3), Point3::origin());
    let img = renderer().render(&scene, &camera, 640, 480).unwrap();
    let face = |p: Point3<f64>| pixel_at(&img, camera.project(&p, 640, 480).unwrap())[0];
    let top = face(Point3::new(0.0, 0.0, 0.2));
    let front = face(Point3::new(-0.2, 0.0, 0.0));
    let side = face(Point3::new(0.0, -0.2, 0.0));
    let differ = |a: u8, b: u8| a.abs_diff(b) >= 10;
    assert!(
        differ(top, front) && differ(front, side) && differ(top, side),
        "{top} {front} {side}"
    );
    // With 4x MSAA a silhouette edge has intermediate shades between box and background.
    if renderer().sample_count() > 1 {
        let bg = Color::BACKGROUND.to_srgb8();
        let mixed = img
            .pixels()
            .filter(|p| {
                let v = p.0[0];
                let lo = v.min(bg[0]).min(front.min(side).min(top));
                v > lo + 8 && v + 8 < bg[0] && !is_background(p.0)
            })
            .count();
        assert!(mixed > 50, "only {mixed} anti-aliased pixels");
    }
}

#[test]
fn png_round_trip_keeps_size_format_and_pixels() {
    let (scene, camera) = two_boxes(BLUE, RED);
    let img = renderer().render(&scene, &camera, W, H).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("boxes.png");
    save_png(&img, &path).unwrap();
    let reader = image::ImageReader::open(&path)
        .unwrap()
        .with_guessed_format()
        .unwrap();
    assert_eq!(reader.format(), Some(image::ImageFormat::Png));
    let back = reader.decode().unwrap();
    assert_eq!(back.color(), image::ColorType::Rgba8);
    assert_eq!(back.to_rgba8(), img);
    // Only the PNG is left in the directory: the temporary file was renamed.
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names, vec![std::ffi::OsString::from("boxes.png")]);
}

#[test]
fn points_are_drawn_in_their_colours_and_hidden_behind_meshes() {
    // A 5x5 grid of points in the plane x = 1, alternately red and blue, 10 px wide.
    let mut points = Vec::new();
    let mut colors = Vec::new();
    for i in 0..5 {
        for j in 0..5 {
            points.push(Point3::new(
                1.0,
                -0.2 + 0.1 * f64::from(i),
                0.3 + 0.1 * f64::from(j),
            ));
            colors.push(if (i + j) % 2 == 0 { RED } else { BLUE });
        }
    }
    let mut scene = RenderScene::new();
    scene.add_points(PointSet::per_point(points.clone(), colors.clone(), 10.0).unwrap());
    // A white box in front of the top-left point (y = 0.2, z = 0.7).
    scene.add_mesh(MeshItem::flat(
        tessellate::cuboid([0.04, 0.04, 0.04]),
        Isometry3::translation(0.8, 0.16, 0.66),
        Color::WHITE,
    ));
    let camera = Camera::look_at(Point3::new(0.0, 0.0, 0.5), Point3::new(1.0, 0.0, 0.5));
    let img = renderer().render(&scene, &camera, 640, 480).unwrap();
    let hidden = Point3::new(1.0, 0.2, 0.7);
    for (p, c) in points.iter().zip(&colors) {
        let px = pixel_at(&img, camera.project(p, 640, 480).unwrap());
        if *p == hidden {
            assert!(!is_red(px) && !is_blue(px), "hidden point shows: {px:?}");
        } else if *c == RED {
            assert!(is_red(px), "{p:?} {px:?}");
        } else {
            assert!(is_blue(px), "{p:?} {px:?}");
        }
    }
    // Halfway between two neighbours (0.1 m apart, far more than 10 px) is background.
    let gap = camera
        .project(&Point3::new(1.0, -0.15, 0.3), 640, 480)
        .unwrap();
    assert!(is_background(pixel_at(&img, gap)));
}

#[test]
fn voxels_are_red_and_grey_cubes_with_outlines() {
    // A row of cubes along y at x = 1: occupied, unknown, occupied, unknown.
    let size = 0.1;
    let centers: Vec<_> = (0..4)
        .map(|i| Point3::new(1.0, -0.15 + 0.1 * f64::from(i), 0.5))
        .collect();
    let colors: Vec<_> = (0..4)
        .map(|i| {
            if i % 2 == 0 {
                Color::OCCUPIED
            } else {
                Color::UNKNOWN
            }
        })
        .collect();
    let mut scene = RenderScene::new();
    scene.add_voxels(VoxelSet::per_voxel(centers.clone(), size, colors).unwrap());
    let camera = Camera::look_at(Point3::new(0.2, 0.3, 0.9), Point3::new(1.0, 0.0, 0.5));
    let img = renderer().render(&scene, &camera, 640, 480).unwrap();
    for (i, c) in centers.iter().enumerate() {
        let px = pixel_at(&img, camera.project(c, 640, 480).unwrap());
        if i % 2 == 0 {
            assert!(is_red(px), "occupied voxel {i}: {px:?}");
        } else {
            let [r, g, b, _] = px.map(i32::from);
            assert!(
                (r - g).abs() < 12 && (g - b).abs() < 12,
                "unknown voxel {i}: {px:?}"
            );
            assert!(!is_background(px) && r > 40, "unknown voxel {i}: {px:?}");
        }
    }
    // The edge between the two front faces of cubes 0 and 1 (x = 0.95, y = -0.1) is darker
    // than the middle of cube 1's front face.
    let face = pixel_at(
        &img,
        camera
            .project(&Point3::new(0.95, -0.05, 0.5), 640, 480)
            .unwrap(),
    );
    let edge = pixel_at(
        &img,
        camera
            .project(&Point3::new(0.95, -0.1, 0.5), 640, 480)
            .unwrap(),
    );
    let lum = |c: [u8; 4]| u32::from(c[0]) + u32::from(c[1]) + u32::from(c[2]);
    assert!(lum(edge) + 30 < lum(face), "edge {edge:?} face {face:?}");
}

#[test]
fn lines_are_thick_and_clipped_at_the_eye() {
    let mut lines = LineSet::new(4.0);
    // A horizontal line across the view at z = 0.6 and x = 1.
    lines.push(Point3::new(1.0, 0.5, 0.6), Point3::new(1.0, -0.5, 0.6), RED);
    // A line from behind the eye to far in front, below the view axis.
    lines.push(
        Point3::new(-1.0, 0.0, 0.3),
        Point3::new(3.0, 0.0, 0.3),
        BLUE,
    );
    let mut scene = RenderScene::new();
    scene.add_lines(lines);
    let camera = Camera::look_at(Point3::new(0.0, 0.0, 0.5), Point3::new(1.0, 0.0, 0.5));
    let img = renderer().render(&scene, &camera, 640, 480).unwrap();
    let on = camera
        .project(&Point3::new(1.0, 0.1, 0.6), 640, 480)
        .unwrap();
    assert!(is_red(pixel_at(&img, on)));
    // 4 px wide: one pixel off the centre line is still red, six pixels off is background.
    let up1 = nalgebra::Point2::new(on.x, on.y - 1.0);
    let up6 = nalgebra::Point2::new(on.x, on.y - 6.0);
    assert!(is_red(pixel_at(&img, up1)));
    assert!(is_background(pixel_at(&img, up6)));
    let ahead = camera
        .project(&Point3::new(1.5, 0.0, 0.3), 640, 480)
        .unwrap();
    assert!(
        is_blue(pixel_at(&img, ahead)),
        "{:?}",
        pixel_at(&img, ahead)
    );
}

#[test]
fn translucent_meshes_blend_over_opaque_ones() {
    let (mut scene, camera) = two_boxes(BLUE, RED);
    let centre = camera.project(&Point3::new(1.5, 0.15, 0.5), W, H).unwrap();
    let before = pixel_at(&renderer().render(&scene, &camera, W, H).unwrap(), centre);
    // A half-transparent white pane in front of the far box's centre, added last but drawn
    // over the opaque boxes whatever the order.
    scene.meshes.insert(
        0,
        MeshItem::flat(
            tessellate::cuboid([0.01, 0.1, 0.1]),
            Isometry3::translation(1.3, 0.15 * 1.3 / 1.5, 0.5),
            Color::WHITE.with_alpha(0.5),
        ),
    );
    let after = pixel_at(&renderer().render(&scene, &camera, W, H).unwrap(), centre);
    let [r, g, b, a] = after.map(i32::from);
    assert_eq!(a, 255);
    // Lightened towards white, but still reddish: the box shows through.
    assert!(is_red(before), "{before:?}");
    assert!(g > i32::from(before[1]) + 60, "{before:?} -> {after:?}");
    assert!(r > g + 10 && (g - b).abs() < 20, "{after:?}");
}

#[test]
fn every_available_backend_draws_the_same_picture() {
    let mut images = Vec::new();
    for backends in [Backends::VULKAN, Backends::GL] {
        let options = RendererOptions {
            backends: Some(backends),
            ..Default::default()
        };
        let Ok(r) = Renderer::with_options(&options) else {
            continue;
        };
        let (scene, camera) = two_boxes(BLUE, RED);
        let img = r.render(&scene, &camera, W, H).unwrap();
        check_two_boxes(&img, &camera, is_blue, is_red);
        images.push((r.adapter_summary(), img));
    }
    assert!(!images.is_empty(), "neither Vulkan nor GL has an adapter");
    for (name, _) in &images {
        println!("drew on {name}");
    }
    if let [(a_name, a), (b_name, b)] = images.as_slice() {
        let diff: u64 = a
            .pixels()
            .zip(b.pixels())
            .map(|(p, q)| {
                p.0.iter()
                    .zip(q.0)
                    .map(|(&x, y)| u64::from(x.abs_diff(y)))
                    .sum::<u64>()
            })
            .sum();
        let mean = diff as f64 / f64::from(W * H * 3);
        println!("{a_name} vs {b_name}: mean difference {mean:.4} per channel");
        assert!(
            mean < 1.0,
            "{a_name} and {b_name} differ by {mean} per channel"
        );
    }
}

#[test]
fn bad_sizes_and_colour_counts_are_errors() {
    let r = renderer();
    let camera = Camera::look_at(Point3::origin(), Point3::new(1.0, 0.0, 0.0));
    let scene = RenderScene::new();
    assert!(matches!(
        r.render(&scene, &camera, 0, 10),
        Err(RenderError::BadSize { .. })
    ));
    assert!(matches!(
        r.render(&scene, &camera, 10, u32::MAX),
        Err(RenderError::BadSize { .. })
    ));
    let mut scene = RenderScene::new();
    scene.add_points(PointSet {
        points: vec![Point3::origin(); 3],
        colors: vec![RED, BLUE],
        size: 2.0,
    });
    assert!(matches!(
        r.render(&scene, &camera, 10, 10),
        Err(RenderError::LengthMismatch {
            expected: 3,
            got: 2,
            ..
        })
    ));
    // An empty scene is all background.
    let img = r.render(&RenderScene::new(), &camera, 7, 5).unwrap();
    assert!(img.pixels().all(|p| is_background(p.0)));
    let _: Rgba<u8> = *img.get_pixel(6, 4);
}

#[cfg(target_os = "linux")]
#[test]
fn a_missing_backend_is_named_in_the_error() {
    let options = RendererOptions {
        backends: Some(Backends::METAL),
        ..Default::default()
    };
    let err = Renderer::with_options(&options).unwrap_err();
    assert!(matches!(err, RenderError::NoAdapter { .. }), "{err}");
    let msg = err.to_string();
    for needle in [
        "no GPU adapter",
        "metal",
        "mesa-vulkan-drivers",
        "libegl-mesa0",
        "WGPU_BACKEND",
    ] {
        assert!(msg.contains(needle), "`{needle}` not in: {msg}");
    }
}

/// Run as a child process with `WGPU_BACKEND=metal` by the test below.
#[cfg(target_os = "linux")]
#[test]
#[ignore = "run by wgpu_backend_env_without_adapter in a child process"]
fn child_renderer_without_adapter() {
    assert_eq!(std::env::var("WGPU_BACKEND").as_deref(), Ok("metal"));
    let err = Renderer::new().unwrap_err();
    assert!(matches!(err, RenderError::NoAdapter { .. }), "{err}");
    assert!(Renderer::optional().is_none());
    println!("CHILD-SAW: {err}");
}

#[cfg(target_os = "linux")]
#[test]
fn wgpu_backend_env_without_adapter() {
    let out = std::process::Command::new(std::env::current_exe().unwrap())
        .args([
            "--exact",
            "child_renderer_without_adapter",
            "--ignored",
            "--nocapture",
        ])
        .env("WGPU_BACKEND", "metal")
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "child failed: {stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        stdout.contains("CHILD-SAW: no GPU adapter (backends tried: metal)"),
        "{stdout}"
    );
}

#[test]
fn one_renderer_serves_many_threads() {
    fn send_sync<T: Send + Sync>() {}
    send_sync::<Renderer>();
    let (scene, camera) = two_boxes(BLUE, RED);
    let images: Vec<RgbaImage> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..3)
            .map(|_| s.spawn(|| renderer().render(&scene, &camera, 320, 240).unwrap()))
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    // Same input, same picture, whichever thread drew it.
    assert!(images.windows(2).all(|w| w[0] == w[1]));
}
