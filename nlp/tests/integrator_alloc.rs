//! `Integrator::to_function` evaluates without allocating once warm (DOPRI5), counted by
//! a global allocator that counts the allocations of the calling thread.
use nlp::integrator::{Integrator, IntegratorOptions};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use symx::{Function, Matrix};

struct Counting;

thread_local! {
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

// SAFETY: every call is forwarded to the system allocator unchanged.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.with(|c| c.set(c.get() + 1));
        System.alloc(layout)
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout)
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, size: usize) -> *mut u8 {
        ALLOCATIONS.with(|c| c.set(c.get() + 1));
        System.realloc(ptr, layout, size)
    }
}

#[global_allocator]
static COUNTING: Counting = Counting;

fn allocations() -> usize {
    ALLOCATIONS.with(|c| c.get())
}

#[test]
fn warm_evaluations_allocate_nothing_and_agree_across_threads() {
    // Van der Pol μ = 1 over [0, 1], and the Jacobian of its end state (level 1).
    let x = Matrix::sym_vec("x", 2);
    let mu = Matrix::sym_vec("mu", 1);
    let ode = Function::new(
        &[&x, &mu],
        &[&[x[1], mu[0] * (1.0 - x[0].sq()) * x[1] - x[0]]],
    )
    .unwrap();
    let int = Integrator::new(&ode, 0.0, 1.0, IntegratorOptions::default()).unwrap();
    let f = int.to_function().unwrap();
    let w = Matrix::sym_vec("w", 3);
    let xf = f.apply(&[&w[..2], &w[2..]]).unwrap().remove(0);
    let jac = symx::jacobian(&xf, &w).unwrap();
    let g = Function::new(&[&w], &[&xf, jac.values()]).unwrap();
    let nnz = jac.values().len();
    let point = [2.0, 0.0, 1.0];
    let mut work = vec![0.0; g.work_size()];
    let (mut a, mut b) = (vec![0.0; 2], vec![0.0; nnz]);
    let mut call = |a: &mut [f64], b: &mut [f64]| {
        g.eval(&[&point], &mut [a, b], &mut work).unwrap();
    };
    call(&mut a, &mut b); // warm: the pools get their buffers
    let first = (a.clone(), b.clone());
    let before = allocations();
    for _ in 0..50 {
        call(&mut a, &mut b);
    }
    assert_eq!(
        allocations() - before,
        0,
        "allocations in 50 warm evaluations"
    );
    assert_eq!(
        (a.clone(), b.clone()),
        first,
        "bit-identical on reused buffers"
    );
    // The same values as a direct simulation.
    let (xs, _) = int.simulate(&point[..2], &point[2..]).unwrap();
    assert_eq!(a, xs);
    // Concurrent callers each get their own buffers and the same results.
    std::thread::scope(|s| {
        let runs: Vec<_> = (0..2)
            .map(|_| {
                s.spawn(|| {
                    let mut work = vec![0.0; g.work_size()];
                    let (mut a, mut b) = (vec![0.0; 2], vec![0.0; nnz]);
                    for _ in 0..20 {
                        g.eval(&[&point], &mut [&mut a, &mut b], &mut work).unwrap();
                    }
                    (a, b)
                })
            })
            .collect();
        for run in runs {
            assert_eq!(run.join().unwrap(), first);
        }
    });
}
