//! Writes the shipped robot-cell scene (`assets/scenes/`): the meshes of an arm of three
//! links and a gripper, a table, a fence and a post, their `.obbt` trees (default build
//! options; the part is the bundled cow), the scene file, and 240 frames of the arm
//! sweeping past the fence, reaching down to the part and back.
//!
//! `cargo run --release --example make_cell` regenerates every file byte for byte (a test
//! checks that rebuilding each shipped tree gives the committed bytes).
// A tool developers run by hand: stopping loudly on a broken input is what it should do.
#![allow(clippy::unwrap_used, clippy::expect_used)]

#[path = "../tests/common/mod.rs"]
mod common;

use obbtree::build::{build, BuildOptions};
use obbtree::mesh::TriMesh;
use obbtree::nalgebra::{Matrix3, Rotation3, Vector3};
use std::fmt::Write as _;
use std::path::Path;

/// Axis-aligned boxes `(center, half)` as one triangle soup, 12 triangles each.
fn boxes(parts: &[([f64; 3], [f64; 3])]) -> TriMesh {
    let mut vertices = Vec::new();
    let mut faces = Vec::new();
    for (center, half) in parts {
        let part = common::cuboid(*half, *center);
        let base = vertices.len() as u32;
        vertices.extend_from_slice(part.vertices());
        faces.extend(part.faces().iter().map(|f| f.map(|v| base + v)));
    }
    TriMesh::new(vertices, faces).expect("valid boxes")
}

/// A closed cylinder along z, `sides` facets, centred at the origin.
fn cylinder(radius: f64, half_height: f64, sides: u32) -> TriMesh {
    let mut vertices = vec![[0.0, 0.0, -half_height], [0.0, 0.0, half_height]];
    for i in 0..sides {
        let a = std::f64::consts::TAU * f64::from(i) / f64::from(sides);
        for z in [-half_height, half_height] {
            vertices.push([radius * a.cos(), radius * a.sin(), z]);
        }
    }
    let ring = |i: u32, top: u32| 2 + 2 * (i % sides) + top;
    let mut faces = Vec::new();
    for i in 0..sides {
        faces.push([0, ring(i + 1, 0), ring(i, 0)]);
        faces.push([1, ring(i, 1), ring(i + 1, 1)]);
        faces.push([ring(i, 0), ring(i + 1, 0), ring(i + 1, 1)]);
        faces.push([ring(i, 0), ring(i + 1, 1), ring(i, 1)]);
    }
    TriMesh::new(vertices, faces).expect("valid cylinder")
}

/// A pose as 12 numbers: rotation row-major, then translation.
fn pose(r: &Matrix3<f64>, t: &Vector3<f64>) -> String {
    let v: Vec<String> = (0..9)
        .map(|k| r[(k / 3, k % 3)])
        .chain(t.iter().copied())
        .map(|x| format!("{}", (x * 1e12).round() / 1e12 + 0.0))
        .collect();
    format!("[{}]", v.join(", "))
}

/// A rigid motion (rotation, translation).
#[derive(Clone, Copy)]
struct Rigid(Matrix3<f64>, Vector3<f64>);

impl Rigid {
    fn then(self, other: Rigid) -> Rigid {
        Rigid(self.0 * other.0, self.0 * other.1 + self.1)
    }
    fn at(x: f64, y: f64, z: f64) -> Rigid {
        Rigid(Matrix3::identity(), Vector3::new(x, y, z))
    }
    fn turn(axis: Vector3<f64>, angle: f64) -> Rigid {
        let r = Rotation3::from_axis_angle(&obbtree::nalgebra::Unit::new_normalize(axis), angle);
        Rigid(*r.matrix(), Vector3::zeros())
    }
}

/// Poses of link1, link2, link3 and the gripper for joint angles (yaw, shoulder, elbow,
/// wrist).
fn arm(q: [f64; 4]) -> [Rigid; 4] {
    let yaw = Rigid::turn(Vector3::z(), q[0]);
    let link1 = yaw.then(Rigid::at(0.0, 0.0, 0.55));
    let shoulder = yaw
        .then(Rigid::at(0.0, 0.0, 0.8))
        .then(Rigid::turn(Vector3::y(), q[1]));
    let link2 = shoulder.then(Rigid::at(0.4, 0.0, 0.0));
    let elbow = shoulder
        .then(Rigid::at(0.8, 0.0, 0.0))
        .then(Rigid::turn(Vector3::y(), q[2]));
    let link3 = elbow.then(Rigid::at(0.3, 0.0, 0.0));
    let wrist = elbow
        .then(Rigid::at(0.6, 0.0, 0.0))
        .then(Rigid::turn(Vector3::y(), q[3]));
    [link1, link2, link3, wrist]
}

/// Joint angles at time `s` in [0, 1]: swing from the fence side over to the table, reach
/// down onto the part, lift, and swing back.
fn joints(s: f64) -> [f64; 4] {
    let smooth = |a: f64, b: f64, t: f64| {
        let t = t.clamp(0.0, 1.0);
        a + (b - a) * t * t * (3.0 - 2.0 * t)
    };
    let deg = f64::to_radians;
    let (yaw, shoulder, elbow);
    if s < 0.35 {
        let t = s / 0.35;
        yaw = smooth(deg(-90.0), deg(0.0), t);
        shoulder = smooth(deg(-20.0), deg(-30.0), t);
        elbow = smooth(deg(60.0), deg(50.0), t);
    } else if s < 0.6 {
        let t = (s - 0.35) / 0.25;
        yaw = 0.0;
        shoulder = smooth(deg(-30.0), deg(-25.0), t);
        elbow = smooth(deg(50.0), deg(53.0), t);
    } else {
        let t = (s - 0.6) / 0.4;
        yaw = smooth(0.0, deg(-90.0), t);
        shoulder = smooth(deg(-25.0), deg(-20.0), t);
        elbow = smooth(deg(53.0), deg(60.0), t);
    }
    // The gripper points straight down.
    [yaw, shoulder, elbow, deg(90.0) - shoulder - elbow]
}

/// How far the fence stands from the base, along -y.
const FENCE: f64 = 1.3;

fn main() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/scenes");
    std::fs::create_dir_all(&dir).unwrap();
    let meshes: Vec<(&str, TriMesh)> = vec![
        ("base", cylinder(0.2, 0.15, 24)),
        ("link1", boxes(&[([0.0; 3], [0.12, 0.12, 0.25])])),
        ("link2", boxes(&[([0.0; 3], [0.4, 0.07, 0.07])])),
        ("link3", boxes(&[([0.0; 3], [0.3, 0.06, 0.06])])),
        (
            "gripper",
            boxes(&[
                ([0.03, 0.0, 0.0], [0.03, 0.1, 0.05]),
                ([0.14, 0.085, 0.0], [0.08, 0.015, 0.04]),
                ([0.14, -0.085, 0.0], [0.08, 0.015, 0.04]),
            ]),
        ),
        ("table", boxes(&[([0.0; 3], [0.6, 0.5, 0.05])])),
        ("fence", boxes(&[([0.0; 3], [1.75, 0.02, 0.6])])),
        ("post", cylinder(0.08, 0.5, 16)),
    ];
    let options = BuildOptions::default();
    for (name, mesh) in &meshes {
        std::fs::write(dir.join(format!("{name}.obj")), common::obj_text(mesh)).unwrap();
        let tree = build(mesh, &options, None).unwrap();
        tree.write_atomic(dir.join(format!("{name}.obbt"))).unwrap();
    }
    let cow = TriMesh::load(&dir.join("../cow.obj")).unwrap();
    build(&cow, &options, None)
        .unwrap()
        .write_atomic(dir.join("cow.obbt"))
        .unwrap();

    let identity = Matrix3::identity();
    let start = arm(joints(0.0));
    let at = |x, y, z| Vector3::new(x, y, z);
    let objects: Vec<(&str, &str, &str, String)> = vec![
        (
            "base",
            "base.obbt",
            "\"robot\"",
            pose(&identity, &at(0.0, 0.0, 0.15)),
        ),
        (
            "link1",
            "link1.obbt",
            "\"robot\"",
            pose(&start[0].0, &start[0].1),
        ),
        (
            "link2",
            "link2.obbt",
            "\"robot\"",
            pose(&start[1].0, &start[1].1),
        ),
        (
            "link3",
            "link3.obbt",
            "\"robot\"",
            pose(&start[2].0, &start[2].1),
        ),
        (
            "gripper",
            "gripper.obbt",
            "\"robot\"",
            pose(&start[3].0, &start[3].1),
        ),
        (
            "table",
            "table.obbt",
            "\"fixtures\"",
            pose(&identity, &at(1.3, 0.0, 0.35)),
        ),
        (
            "fence",
            "fence.obbt",
            "\"fixtures\"",
            pose(&identity, &at(0.25, -FENCE, 0.6)),
        ),
        (
            "post",
            "post.obbt",
            "\"fixtures\"",
            pose(&identity, &at(-0.8, 0.7, 0.5)),
        ),
        // The cow rests on the table, its hooves 5 mm into the top (z = 0.4).
        (
            "part",
            "cow.obbt",
            "\"parts\"",
            pose(&identity, &at(1.3, 0.0, 0.4 + 0.162908 - 0.005)),
        ),
    ];
    let mut toml = String::from(
        "# A small robot cell: an arm (base, three links, a gripper) sweeping past a fence,\n\
         # reaching down to a part (the bundled cow) on a table, and back. Generated by\n\
         # `cargo run --release --example make_cell`; run it with\n\
         #   obbtree scene assets/scenes/cell.toml\n\n\
         frames = \"cell.jsonl\"\n",
    );
    for (name, asset, group, p) in &objects {
        write!(
            toml,
            "\n[[object]]\nname = \"{name}\"\nasset = \"{asset}\"\ngroups = [{group}]\npose = {p}\n"
        )
        .unwrap();
    }
    toml.push_str(
        r#"
# Links of the arm never collide with each other (they are jointed): no rule, no test.

# The arm must keep 5 cm from every fixture: the tolerance query, stopped at the first
# pair closer than that.
[[rule]]
a = "robot"
b = "fixtures"
effect = "clearance"
clearance = 0.05

# Any link touching the part is a collision: first contact only.
[[rule]]
a = "robot"
b = "parts"
effect = "contact"

# The gripper against the part: every contacting triangle pair (the grasp).
[[rule]]
a = "gripper"
b = "part"
effect = "contacts"

# A range sensor on the gripper: its distance to the table while within 30 cm.
[[rule]]
a = "gripper"
b = "table"
effect = "distance"
max_distance = 0.3

# The part must stay on the table: contact (both static, so answered once and reused).
[[rule]]
a = "part"
b = "table"
effect = "contact"

# How far the base is from the far end of the part: the span (static, reused).
[[rule]]
a = "base"
b = "part"
effect = "span"
"#,
    );
    std::fs::write(dir.join("cell.toml"), toml).unwrap();

    let frames = 240;
    let mut lines = String::new();
    for k in 0..frames {
        let links = arm(joints(f64::from(k) / f64::from(frames - 1)));
        let names = ["link1", "link2", "link3", "gripper"];
        let entries: Vec<String> = names
            .iter()
            .zip(links)
            .map(|(n, l)| format!("\"{n}\": {}", pose(&l.0, &l.1)))
            .collect();
        writeln!(lines, "{{\"poses\": {{{}}}}}", entries.join(", ")).unwrap();
    }
    std::fs::write(dir.join("cell.jsonl"), lines).unwrap();
    println!("wrote {}", dir.display());
}
