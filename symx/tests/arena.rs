//! `with_fresh_arena`: a build in a graph of its own, whose memory is released at the end
//! of the scope while the functions compiled inside keep working; scopes nest, and the
//! outer graph survives a panic inside. Live heap bytes are counted per thread by a
//! counting global allocator.
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use symx::{gradient, node_count, with_fresh_arena, Expr, Function, Matrix};

struct Counting;

thread_local! {
    static LIVE: Cell<isize> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let _ = LIVE.try_with(|c| c.set(c.get() + layout.size() as isize));
        System.alloc(layout)
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        let _ = LIVE.try_with(|c| c.set(c.get() - layout.size() as isize));
        System.dealloc(ptr, layout)
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn live() -> isize {
    LIVE.with(Cell::get)
}

/// The Rosenbrock chain on `n` variables and its gradient, compiled.
fn chain(n: usize) -> Function {
    let x = Matrix::sym_vec("x", n);
    let f: Expr = (0..n - 1)
        .map(|i| (1.0 - x[i]).sq() + 100.0 * (x[i + 1] - x[i].sq()).sq())
        .sum();
    let g = gradient(f, &x).unwrap();
    Function::new(&[&x], &[&[f], &g]).unwrap()
}

#[test]
fn a_scope_releases_its_graph_and_keeps_its_functions() {
    let outer = Expr::sym("outer") * 2.0;
    let (nodes0, live0) = (node_count(), live());
    let (f, nodes_inside, live_inside) = with_fresh_arena(|| {
        let f = chain(2000);
        (f, node_count(), live())
    });
    let function_bytes = live() - live0;
    assert_eq!(node_count(), nodes0);
    assert!(nodes_inside > 10_000, "{nodes_inside} nodes");
    // What stays is the compiled function (its tape), a fraction of the graph built.
    assert!(
        function_bytes * 3 < live_inside - live0,
        "kept {function_bytes} of {} bytes",
        live_inside - live0
    );
    let x = vec![0.5; 2000];
    let out = f.call(&[&x]).unwrap();
    // f at x = 0.5: 1999 · (0.25 + 100 · 0.0625) = 1999 · 6.5.
    assert_eq!(out[0][0], 1999.0 * 6.5);
    assert_eq!(out[1].len(), 2000);
    // The same function built in this thread's graph computes the same numbers.
    assert_eq!(chain(2000).call(&[&x]).unwrap(), out);
    // The outer graph is intact.
    assert_eq!(outer.to_string(), "(outer*2)");
}

#[test]
fn scopes_nest_and_survive_a_panic() {
    let y = Expr::sym("y");
    let before = node_count();
    let (inner_f, middle_nodes) = with_fresh_arena(|| {
        let z = Expr::sym("z");
        let e = z.exp() + 1.0;
        let at_middle = node_count();
        let inner_f = with_fresh_arena(|| {
            assert_eq!(node_count(), 2); // a fresh graph holds only the constants 0 and 1
            let w = Expr::sym("w");
            Function::new(&[&[w]], &[&[w.cos()]]).unwrap()
        });
        assert_eq!(node_count(), at_middle);
        assert_eq!(e.to_string(), "(1+exp(z))");
        (inner_f, at_middle)
    });
    assert!(middle_nodes >= 4);
    assert_eq!(node_count(), before);
    assert_eq!(inner_f.call(&[&[0.0]]).unwrap()[0][0], 1.0);
    let r = std::panic::catch_unwind(|| {
        with_fresh_arena(|| {
            let _ = Expr::sym("doomed").sin();
            panic!("inside a scope");
        })
    });
    assert!(r.is_err());
    assert_eq!(node_count(), before);
    assert_eq!((y + 1.0).to_string(), "(1+y)");
}
