//! State counts of the family (docs/physics.md section 5): `nsection` n+6 frozen / 2n+8 full,
//! `cv1` 5 with both closures (no links: its mass is a constant), `cv2` 6 / 8, `schmidt` 4;
//! and the state layout `[x, v, y, w, P_1..P_ncv, m_1..m_ncv]`.

use stirling::dsl::{Closure, Model, StateKind};
use stirling::models::build;

fn count(name: &str, n: Option<usize>, closure: Closure) -> usize {
    build(name, n, closure).expect("a family member").n_states()
}

#[test]
fn nsection_has_n_plus_6_frozen_and_2n_plus_8_full() {
    for n in [1, 2, 3, 4, 7, 10, 25] {
        assert_eq!(
            count("nsection", Some(n), Closure::Frozen),
            n + 6,
            "nsection n = {n}, frozen"
        );
        assert_eq!(
            count("nsection", Some(n), Closure::Full),
            2 * n + 8,
            "nsection n = {n}, full"
        );
    }
}

#[test]
fn scalar_members_have_the_seed_counts() {
    for closure in [Closure::Full, Closure::Frozen] {
        assert_eq!(count("schmidt", None, closure), 4, "schmidt {closure}");
        assert_eq!(
            count("cv1", None, closure),
            5,
            "cv1 {closure}: no links, so no mass state"
        );
    }
    assert_eq!(count("cv2", None, Closure::Frozen), 6);
    assert_eq!(count("cv2", None, Closure::Full), 8);
}

#[test]
fn order_aliases_count_as_the_seed_does() {
    for (alias, order) in [
        ("order4", 4),
        ("order5", 5),
        ("order6", 6),
        ("order7", 7),
        ("order8", 8),
    ] {
        assert_eq!(count(alias, None, Closure::Frozen), order, "{alias}");
    }
    assert_eq!(build("order8", None, Closure::Frozen).unwrap().n(), 2);
}

/// Positions and velocities first, then one pressure per CV, then (full) one mass per CV.
fn assert_layout(m: &dyn Model, ncv: usize) {
    let kinds: Vec<StateKind> = m.states().iter().map(|s| s.kind).collect();
    let mut expected = vec![
        StateKind::Position(0),
        StateKind::Velocity(0),
        StateKind::Position(1),
        StateKind::Velocity(1),
    ];
    if m.name() != "schmidt" {
        expected.extend((0..ncv).map(StateKind::Pressure));
        if m.closure() == Closure::Full && m.name() != "cv1" {
            expected.extend((0..ncv).map(StateKind::Mass));
        }
    }
    assert_eq!(kinds, expected, "{} {}", m.name(), m.closure());
    let units: Vec<&str> = m.states().iter().map(|s| s.unit).collect();
    for (k, u) in kinds.iter().zip(units) {
        let want = match k {
            StateKind::Position(_) => "m",
            StateKind::Velocity(_) => "m/s",
            StateKind::Pressure(_) => "Pa",
            StateKind::Mass(_) => "kg",
            StateKind::WallTemperature(_) => "K",
        };
        assert_eq!(u, want, "{} {k:?}", m.name());
    }
}

#[test]
fn state_layout_follows_physics_md() {
    for closure in [Closure::Full, Closure::Frozen] {
        assert_layout(build("schmidt", None, closure).unwrap().as_ref(), 0);
        assert_layout(build("cv1", None, closure).unwrap().as_ref(), 1);
        assert_layout(build("cv2", None, closure).unwrap().as_ref(), 2);
        for n in [1, 2, 3, 10] {
            assert_layout(build("nsection", Some(n), closure).unwrap().as_ref(), n + 2);
        }
    }
}

#[test]
fn every_state_says_what_it_is() {
    let m = build("nsection", Some(3), Closure::Full).unwrap();
    for s in m.states() {
        assert!(
            !s.meaning.trim().is_empty(),
            "state {} has no meaning",
            s.name
        );
    }
    let names = m.state_names();
    let mut unique = names.clone();
    unique.sort();
    unique.dedup();
    assert_eq!(
        unique.len(),
        names.len(),
        "state names must be unique: {names:?}"
    );
}
