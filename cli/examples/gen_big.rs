//! Times the generator at scale: `cargo run --release --example gen_big -- 1001 500`
//! (n = 2 (nx·ny − ny) ≈ 10^6).
fn main() {
    let a: Vec<usize> = std::env::args()
        .skip(1)
        .map(|s| s.parse().unwrap())
        .collect();
    let spec = fricont_exchange::generator::RectSpec {
        nx: a[0],
        ny: a[1],
        ..Default::default()
    };
    let t = std::time::Instant::now();
    let c = fricont_exchange::generator::generate(&spec).unwrap();
    println!(
        "n = {}, p = {}, nnz(A) = {}, generated in {:.2} s",
        c.n(),
        c.p(),
        c.a.nnz(),
        t.elapsed().as_secs_f64()
    );
}
