//! `Integrator::to_function` evaluates without allocating once warm (DOPRI5 and SDIRK4),
//! counted by a global allocator that counts the allocations of the calling thread.
use nlp::integrator::{Integrator, IntegratorOptions, Method};
use symx::{Function, Matrix};
use testkit::alloc::ThreadCounting;

#[global_allocator]
static GLOBAL: ThreadCounting = ThreadCounting;

#[test]
fn warm_evaluations_allocate_nothing_and_agree_across_threads() {
    check(Method::Dopri5);
}

#[test]
fn warm_sdirk4_evaluations_allocate_nothing_and_agree_across_threads() {
    // Its LU factors live in the kept buffers too (faer's LU in place).
    check(Method::Sdirk4);
}

fn check(method: Method) {
    // Van der Pol μ = 1 over [0, 1], and the Jacobian of its end state (level 1).
    let x = Matrix::sym_vec("x", 2);
    let mu = Matrix::sym_vec("mu", 1);
    let ode = Function::new(
        &[&x, &mu],
        &[&[x[1], mu[0] * (1.0 - x[0].sq()) * x[1] - x[0]]],
    )
    .unwrap();
    let options = IntegratorOptions {
        method,
        ..Default::default()
    };
    let int = Integrator::new(&ode, 0.0, 1.0, options).unwrap();
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
    let (_, count) = ThreadCounting::during(|| {
        for _ in 0..50 {
            call(&mut a, &mut b);
        }
    });
    assert_eq!(count, 0, "allocations in 50 warm evaluations");
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
