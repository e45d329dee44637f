//! Mistakes in the kinematic items of an engine file (`flywheel`, `crank`, `linkage`; docs/physics.md
//! section 12): each refused at the user's tokens with `path:line:column: message` and a caret,
//! as `tests/files_errors.rs` does for the other items (snapshots
//! `tests/snapshots/files_errors_kinematic__*.snap`). The macro gives the same messages
//! (`tests/ui/kinematic_*.rs`).

use std::path::PathBuf;

use stirling::models::files::BASES;
use stirling_front::load::{load_str, LoadError};

/// A small valid kinematic engine: one gas volume under a piston on a crank. Each case
/// changes one line.
const GOOD: &str = r#"/// A user's kinematic engine.
model Mine {
    name "mine";
    params {
        /// gas constant
        R: 287.0 "J/(kg K)",
        /// heat-capacity ratio
        gamma: 1.4 "-",
        /// charge pressure
        P0: 1.0e5 "Pa",
        /// wall temperature
        T0: 300.0 "K",
        /// flywheel inertia
        J: 1.0e-4 "kg m^2",
        /// crank radius
        r: 0.01 "m",
        /// connecting rod
        L: 0.05 "m",
        /// piston area
        A: 1.0e-3 "m^2",
    }
    gas { R: R, gamma: gamma, charge: P0, mdot_eps: 1.0e-6 }
    flywheel wheel(theta, omega) { inertia: J, damper: 1.0e-5 }
    crank piston(y) on wheel { radius: r, rod: L, phase: 0.0 }
    cv gas { volume: 2.0e-4, faces { piston: -A }, port wall { h: 10.0, area: 0.01, wall: T0 } }
}
"#;

fn edit(from: &str, to: &str) -> String {
    assert!(GOOD.contains(from), "`{from}` not in the engine");
    GOOD.replacen(from, to, 1)
}

fn refused(name: &str, text: &str) -> LoadError {
    let path = PathBuf::from(format!("bad/{name}.stirling"));
    match load_str(&path, text, BASES) {
        Ok(_) => panic!("{name}: loaded"),
        Err(e) => e,
    }
}

/// The first diagnostic is at `line:column` and says `says`; the snapshot holds the rendering.
fn check(name: &str, text: &str, line: usize, column: usize, says: &str) {
    let e = refused(name, text);
    let rendered = e.to_string();
    let path = format!("bad/{name}.stirling");
    let d = e
        .diagnostics()
        .iter()
        .find(|d| (d.line, d.column) == (line, column))
        .cloned()
        .unwrap_or_else(|| panic!("{name}: nothing at {line}:{column} in {rendered}"));
    assert_eq!(d.path, path, "{rendered}");
    assert!(d.message.contains(says), "{name}: {rendered}");
    assert!(rendered.contains('^'), "no caret: {rendered}");
    insta::assert_snapshot!(name, rendered);
}

#[test]
fn the_good_engine_loads() {
    let path = PathBuf::from("good/mine.stirling");
    let topo = load_str(&path, GOOD, BASES).expect("loads");
    assert_eq!(topo.mechanisms.len(), 1);
    assert!(topo.bodies[0].rotary);
}

/// A sensor on the flywheel reads its angle in rad and its speed in rad/s by default.
#[test]
fn flywheel_sensors_default_to_radians() {
    let text = edit(
        "    cv gas {",
        "    sensor angle: theta;\n    sensor speed: omega;\n    cv gas {",
    );
    let topo = load_str(&PathBuf::from("good/sensed.stirling"), &text, BASES).expect("loads");
    let units: Vec<(&str, &str)> = topo
        .sensors
        .iter()
        .map(|s| (s.name.as_str(), s.unit.as_str()))
        .collect();
    assert_eq!(units, [("angle", "rad"), ("speed", "rad/s")]);
}

#[test]
fn crank_on_an_unknown_flywheel() {
    let text = edit("on wheel {", "on wheeel {");
    check(
        "crank_unknown_flywheel",
        &text,
        24,
        24,
        "unknown flywheel `wheeel`: expected `wheel`",
    );
}

#[test]
fn crank_on_a_body() {
    let text = edit(
        "    crank piston(y)",
        "    body slider(z, u) { mass: 1.0 }\n    crank piston(y)",
    );
    let text = text.replacen("on wheel {", "on slider {", 1);
    check("crank_on_a_body", &text, 25, 24, "`slider` is a body");
}

#[test]
fn rod_shorter_than_the_crank() {
    let text = edit("rod: L,", "rod: 0.5 * r,");
    check(
        "crank_rod_too_short",
        &text,
        24,
        48,
        "must be longer than the crank radius",
    );
}

#[test]
fn crank_without_a_rod() {
    let text = edit("rod: L, ", "");
    check("crank_without_rod", &text, 24, 11, "has no `rod`");
}

#[test]
fn linkage_reading_another_state() {
    let text = edit(
        "crank piston(y) on wheel { radius: r, rod: L, phase: 0.0 }",
        "linkage piston(y) on wheel { position: r * sin(theta) * omega }",
    );
    check(
        "linkage_reads_speed",
        &text,
        24,
        44,
        "an expression of the angle `theta`",
    );
}

#[test]
fn face_on_the_flywheel() {
    let text = edit("faces { piston: -A }", "faces { wheel: -A }");
    check("face_on_flywheel", &text, 25, 38, "`wheel` is a flywheel");
}

#[test]
fn flywheel_friction_without_its_scale() {
    let text = edit("damper: 1.0e-5 }", "damper: 1.0e-5, friction: 1.0e-4 }");
    check(
        "flywheel_friction_without_scale",
        &text,
        23,
        64,
        "needs `omega_eps`",
    );
}
