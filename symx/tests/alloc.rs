//! Evaluating a compiled function that calls other functions (nested), and a lookup
//! table, allocates nothing: a counting global allocator (counting only on the thread and
//! during the span under test) must see zero allocations.
use symx::{gradient, hessian, Function, Interpolant, Matrix};
use testkit::alloc::ThreadCounting;

#[global_allocator]
static GLOBAL: ThreadCounting = ThreadCounting;

fn allocations_during(f: impl FnOnce()) -> usize {
    ThreadCounting::during(f).1
}

#[test]
fn evaluation_with_calls_allocates_nothing() {
    let x = Matrix::sym_vec("x", 2);
    let table = Interpolant::bspline(&[0.0, 1.0, 2.0, 3.0], &[0.0, 1.0, 0.5, 2.0]).unwrap();
    let inner = Function::new(&[&x], &[&[table.eval(x[0]) * x[1], x[1].sin()]]).unwrap();
    let y = inner.apply(&[&x]).unwrap().remove(0);
    let outer = Function::new(&[&x], &[&[y[0] + y[1] * x[0]]]).unwrap();
    let z = Matrix::sym_vec("z", 2);
    let mut e = z[0];
    for _ in 0..3 {
        e = outer.apply(&[&[e, z[1]]]).unwrap()[0][0];
    }
    let g = gradient(e, &z).unwrap();
    let h = hessian(e, &z).unwrap();
    let f = Function::new(&[&z], &[&[e], &g, h.values()]).unwrap();
    let mut work = vec![0.0; f.work_size()];
    let (mut v, mut gv, mut hv) = ([0.0], [0.0; 2], vec![0.0; h.nnz()]);
    let n = allocations_during(|| {
        f.eval(&[&[0.7, 1.3]], &mut [&mut v, &mut gv, &mut hv], &mut work)
            .unwrap();
    });
    assert_eq!(n, 0);
    assert!(v[0].is_finite() && gv.iter().chain(&hv).all(|d| d.is_finite()));
    // (The counter works: building a vector is seen.)
    assert!(allocations_during(|| drop(std::hint::black_box(vec![1u8; 10]))) > 0);
}
