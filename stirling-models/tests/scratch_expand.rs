#[test]
fn show() {
    let topo = stirling_front::load::load_file(std::path::Path::new("../examples/engines/nsection_fx.stirling"), stirling_models::files::BASES).unwrap();
    let spec = stirling_dsl::codegen::ModelSpec { ident: proc_macro2::Ident::new("X", proc_macro2::Span::call_site()), vis: quote::quote!(pub), krate: quote::quote!(::stirling_dsl) };
    let ts = stirling_dsl::codegen::generate(topo, &spec);
    let s = ts.to_string();
    let i = s.find("fn __vessels_frozen").unwrap();
    let j = s[i..].find("fn __mech_frozen").unwrap();
    println!("{}", &s[i..i + j]);
}
