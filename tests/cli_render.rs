//! `nbv render scene|cloud|map` end to end: PNG size and format, and pixels where the
//! picture must show something — an object's colour at its projected centre, a box top's
//! occupied voxel in red, each cloud's colour — and background where nothing is drawn.
//! Needs a GPU or Mesa's software drivers (installed by `.ci/run`).

mod common;

use common::{boxes, nbv, synthetic_cloud, text};
use image::RgbaImage;
use nalgebra::Point3;
use nbv_core::cloud::PointCloud;
use nbv_core::cloud::io::{WriteOptions, write_cloud};
use nbv_sim::render::{
    Camera, Color, fitted_front_and_back, front_and_back, object_color, scene_items,
};
use std::path::Path;

const W: u32 = 1280;
const H: u32 = 960;

fn png(path: &Path) -> RgbaImage {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(
        &bytes[..8],
        b"\x89PNG\r\n\x1a\n",
        "{} is not a PNG",
        path.display()
    );
    image::load_from_memory(&bytes).unwrap().to_rgba8()
}

fn pixel(img: &RgbaImage, cam: &Camera, p: &Point3<f64>) -> [u8; 4] {
    let q = cam.project(p, img.width(), img.height()).unwrap();
    img.get_pixel(q.x as u32, q.y as u32).0
}

fn is_background(c: [u8; 4]) -> bool {
    let want = Color::BACKGROUND.to_srgb8();
    (0..3).all(|i| (i32::from(c[i]) - i32::from(want[i])).abs() <= 2)
}

/// Same hue family as `want`: the channel order matches and the colour is not grey (the
/// lighting changes brightness, not hue).
fn has_hue_of(c: [u8; 4], want: Color) -> bool {
    let w = want.to_srgb8();
    let order = |v: [u8; 4]| {
        let mut idx = [0usize, 1, 2];
        idx.sort_by_key(|&i| std::cmp::Reverse(v[i]));
        idx
    };
    let spread = |v: [u8; 4]| {
        i32::from(*v[..3].iter().max().unwrap()) - i32::from(*v[..3].iter().min().unwrap())
    };
    order(c)[0] == order(w)[0] && spread(c) > spread(w) / 3
}

fn run_ok(args: &[&str]) -> String {
    let o = nbv(args);
    assert!(
        o.status.success(),
        "nbv {args:?}: {}\n{}",
        text(&o.stdout),
        text(&o.stderr)
    );
    text(&o.stdout)
}

#[test]
fn scene_pictures_show_the_objects() {
    let tmp = tempfile::tempdir().unwrap();
    let (front, back) = (tmp.path().join("front.png"), tmp.path().join("back.png"));
    run_ok(&[
        "render",
        "scene",
        "--scene",
        "paper-env1",
        "-o",
        front.to_str().unwrap(),
        "--back",
        back.to_str().unwrap(),
    ]);
    let (f, b) = (png(&front), png(&back));
    assert_eq!(f.dimensions(), (W, H));
    assert_eq!(b.dimensions(), (W, H));

    // The same cameras as the command: framing everything the scene draws.
    let scene = nbv_scenes::builtin::load("paper-env1").unwrap();
    let items = scene_items(&scene).unwrap();
    let (cf, cb) = fitted_front_and_back(&items, f64::from(W) / f64::from(H));
    let meshes = scene.object_meshes().unwrap();
    // The jug (object 0) stands in front, seen whole from the front-left.
    let (lo, hi) = meshes[0].bounds().unwrap();
    let jug = nalgebra::center(&lo, &hi);
    let c = pixel(&f, &cf, &jug);
    assert!(has_hue_of(c, object_color(0)), "jug pixel {c:?}");
    // Every object's centre is drawn over (object, table or obstacle: not background).
    for m in &meshes {
        let (lo, hi) = m.bounds().unwrap();
        assert!(!is_background(pixel(&f, &cf, &nalgebra::center(&lo, &hi))));
    }
    // Seen from the back, the jug is behind the bottle or the panel or visible: never
    // background; the image corners are background in both pictures.
    assert!(!is_background(pixel(&b, &cb, &jug)));
    for img in [&f, &b] {
        for (x, y) in [(2, 2), (W - 3, 2)] {
            assert!(is_background(img.get_pixel(x, y).0), "corner ({x}, {y})");
        }
    }
}

#[test]
fn cloud_pictures_colour_each_file() {
    let tmp = tempfile::tempdir().unwrap();
    let all = synthetic_cloud(false);
    // File A: the table; file B: what stands on it.
    let on_table = |keep: bool| -> PointCloud {
        all.retain_indices(|i| (all.points[i].z > common::table_top() + 0.005) == keep)
    };
    let (a, b) = (tmp.path().join("a.ply"), tmp.path().join("b.ply"));
    write_cloud(&a, &on_table(false), &WriteOptions::default()).unwrap();
    write_cloud(&b, &on_table(true), &WriteOptions::default()).unwrap();
    let out = tmp.path().join("clouds.png");
    let stdout = run_ok(&[
        "render",
        "cloud",
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(stdout.contains("colour #"), "{stdout}");
    let img = png(&out);
    assert_eq!(img.dimensions(), (W, H));
    let count = |want: Color| img.pixels().filter(|p| has_hue_of(p.0, want)).count();
    let (na, nb) = (count(Color::categorical(0)), count(Color::categorical(1)));
    assert!(na > 20_000, "file A colour: {na} pixels");
    assert!(nb > 2_000, "file B colour: {nb} pixels");

    let o = nbv(&["render", "cloud", "-o", out.to_str().unwrap()]);
    assert!(!o.status.success());
}

#[test]
fn map_pictures_show_occupied_voxels_red_and_unknown_grey() {
    let tmp = tempfile::tempdir().unwrap();
    let cloud = tmp.path().join("cloud.ply");
    write_cloud(&cloud, &synthetic_cloud(true), &WriteOptions::default()).unwrap();
    let map = tmp.path().join("map");
    run_ok(&[
        "map",
        "--cloud",
        cloud.to_str().unwrap(),
        "-o",
        map.to_str().unwrap(),
    ]);
    let (front, back) = (tmp.path().join("front.png"), tmp.path().join("back.png"));
    let stdout = run_ok(&[
        "render",
        "map",
        map.to_str().unwrap(),
        "-o",
        front.to_str().unwrap(),
        "--back",
        back.to_str().unwrap(),
    ]);
    assert!(stdout.contains("unknown crust voxels"), "{stdout}");
    let (f, b) = (png(&front), png(&back));
    assert_eq!((f.dimensions(), b.dimensions()), ((W, H), (W, H)));
    // Cameras of the default workspace.
    let (lo, hi) = (
        Point3::new(0.30, -0.70, 0.23),
        Point3::new(1.50, 0.70, 0.83),
    );
    let (cf, _) = front_and_back(lo, hi, f64::from(W) / f64::from(H));
    // The middle of each box's top face is an occupied voxel, seen from the front.
    for (blo, bhi) in boxes() {
        let top = Point3::new(
            (blo[0] + bhi[0]) / 2.0,
            (blo[1] + bhi[1]) / 2.0,
            bhi[2] + 0.01,
        );
        let c = pixel(&f, &cf, &top);
        assert!(
            has_hue_of(c, Color::OCCUPIED) && c[0] > 120,
            "box top {c:?}"
        );
    }
    let grey = |img: &RgbaImage| {
        img.pixels()
            .filter(|p| {
                let [r, g, bl, _] = p.0.map(i32::from);
                (r - g).abs() < 8 && (g - bl).abs() < 8 && (60..200).contains(&r)
            })
            .count()
    };
    let red = |img: &RgbaImage| {
        img.pixels()
            .filter(|p| has_hue_of(p.0, Color::OCCUPIED))
            .count()
    };
    for img in [&f, &b] {
        assert!(
            red(img) > 20_000 && grey(img) > 20_000,
            "red {} grey {}",
            red(img),
            grey(img)
        );
        assert!(is_background(img.get_pixel(2, 2).0));
    }

    let o = nbv(&[
        "render",
        "map",
        tmp.path().to_str().unwrap(),
        "-o",
        front.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(text(&o.stderr).contains("grid.nbvgrid"));
}

#[test]
fn without_an_adapter_render_fails_naming_mesa_and_map_only_warns() {
    let tmp = tempfile::tempdir().unwrap();
    let png_path = tmp.path().join("scene.png");
    // No Metal on Linux: wgpu finds no adapter at all.
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_nbv"))
        .args(["render", "scene", "--scene", "paper-env1", "-o"])
        .arg(&png_path)
        .env("WGPU_BACKEND", "metal")
        .output()
        .unwrap();
    assert!(!o.status.success());
    let err = text(&o.stderr);
    assert!(
        err.contains("no GPU adapter") && err.contains("mesa-vulkan-drivers"),
        "{err}"
    );
    assert!(!png_path.exists());

    let cloud = tmp.path().join("cloud.ply");
    write_cloud(&cloud, &synthetic_cloud(true), &WriteOptions::default()).unwrap();
    let map = tmp.path().join("map");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_nbv"))
        .args(["map", "--pictures", "--cloud"])
        .arg(&cloud)
        .arg("-o")
        .arg(&map)
        .env("WGPU_BACKEND", "metal")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(text(&o.stderr).contains("warning: pictures skipped: no GPU adapter"));
    assert!(map.join("grid.nbvgrid").exists() && !map.join("map_front.png").exists());
}
