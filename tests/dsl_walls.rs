//! Walls with a temperature state (thermal masses) declared with `stirling_model!`: the
//! generated Jacobians against finite differences, the energy budget with the walls' `C Tw`,
//! and the limits of large and small capacity.

mod common;
#[path = "dsl_walls/models.rs"]
mod models;

use models::{Fixed, HeadMatrix, HeadWall, MatrixWall};
use stirling::dsl::{Closure, Model, StateKind};

#[test]
fn rest_state_is_an_equilibrium() {
    for n in [1, 2, 3, 10] {
        let models: [Box<dyn Model>; 4] = [
            Box::new(Fixed::new(n, Closure::Full).unwrap()),
            Box::new(HeadWall::new(n, Closure::Full).unwrap()),
            Box::new(MatrixWall::new(n, Closure::Full).unwrap()),
            Box::new(HeadMatrix::new(n, Closure::Full).unwrap()),
        ];
        for m in &models {
            let p = m.default_params();
            let mut x = vec![0.0; m.n_states()];
            m.equilibrium_guess(&p, &mut x);
            let mut f = vec![0.0; m.n_states()];
            m.rhs(&p, &x, 0.0, &mut f);
            for ((s, fi), xi) in m.states().iter().zip(&f).zip(&x) {
                let scale = match s.kind {
                    StateKind::Pressure(_) => 1e5,
                    StateKind::WallTemperature(_) => *xi,
                    _ => 1.0,
                };
                assert!(
                    fi.abs() <= 1e-9 * scale,
                    "{} n={n}: {}' = {fi:e} at rest",
                    m.name(),
                    s.name
                );
            }
        }
    }
}
