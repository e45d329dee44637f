use std::time::Instant;
use stirling_dsl::Closure;
use stirling_models::linear::*;
use nalgebra::DMatrix;
fn main() {
    let model = stirling_models::build("nsection", Some(1000), Closure::Full).unwrap();
    let p = model.default_params();
    let t = Instant::now();
    let eq = equilibrium::solve(model.as_ref(), &p, &NewtonOptions::default()).unwrap();
    let n = model.n_states();
    let j = DMatrix::from_vec(n, n, model.jacobian_dense(&p, &eq.x, 0.0));
    println!("eq+jac {:?}", t.elapsed());
    let t = Instant::now();
    let r = reduce::reduce(&j, &equilibrium::mass_states(model.as_ref()));
    println!("reduce {:?}", t.elapsed());
    let t = Instant::now();
    let (b, _) = balance::balance(&r.a);
    println!("balance {:?}", t.elapsed());
    let t = Instant::now();
    let ev = poles::eigenvalues(&r.a).unwrap();
    println!("eig {:?}", t.elapsed());
    let t = Instant::now();
    let _ = poles::to_poles(ev);
    println!("to_poles {:?}", t.elapsed());
    let _ = b;
}
