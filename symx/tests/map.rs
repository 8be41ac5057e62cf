//! `Function::map`: many points, serial or over threads; the results must be
//! bit-identical to `eval_batch` (the same tape on the same numbers) for any split.
use symx::{Function, Matrix, SymxError};

fn function() -> Function {
    let x = Matrix::sym_vec("x", 3);
    let p = Matrix::sym_vec("p", 1);
    let y = vec![
        x[0].sin() * p[0] + x[1].exp(),
        x.sumsqr().sqrt(),
        x[2].erf() * x[0],
    ];
    Function::new(&[&x, &p], &[&y, &[x[1] * p[0]]]).unwrap()
}

#[test]
fn parallel_map_is_bit_identical_to_the_serial_batch() {
    let f = function();
    for n in [1usize, 2, 7, 100] {
        let xs: Vec<f64> = (0..3 * n).map(|i| (i as f64 * 0.37).sin()).collect();
        let ps: Vec<f64> = (0..n).map(|i| i as f64 * 0.5 - 1.0).collect();
        let (mut y_ref, mut z_ref) = (vec![0.0; 3 * n], vec![0.0; n]);
        let mut work = vec![0.0; f.work_size()];
        f.eval_batch(&[&xs, &ps], &mut [&mut y_ref, &mut z_ref], &mut work, n)
            .unwrap();
        for threads in [1usize, 2, 3, 8] {
            let map = f.map(n).parallel(threads).unwrap();
            let (mut y, mut z) = (vec![f64::NAN; 3 * n], vec![f64::NAN; n]);
            let mut work = vec![0.0; map.work_size()];
            map.eval(&[&xs, &ps], &mut [&mut y, &mut z], &mut work)
                .unwrap();
            let same =
                |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(a, b)| a.to_bits() == b.to_bits());
            assert!(
                same(&y, &y_ref) && same(&z, &z_ref),
                "n {n}, threads {threads}"
            );
        }
    }
}

#[test]
fn map_rejects_bad_sizes() {
    let f = function();
    let map = f.map(4).parallel(2).unwrap();
    let mut work = vec![0.0; map.work_size()];
    let (mut y, mut z) = (vec![0.0; 12], vec![0.0; 4]);
    let xs = vec![0.0; 11];
    let r = map.eval(&[&xs, &[0.0; 4]], &mut [&mut y, &mut z], &mut work);
    assert!(matches!(
        r,
        Err(SymxError::Length {
            what: "input",
            index: 0,
            expected: 12,
            got: 11
        })
    ));
    let mut short = vec![0.0; map.work_size() - 1];
    let r = map.eval(&[&[0.0; 12], &[0.0; 4]], &mut [&mut y, &mut z], &mut short);
    assert!(matches!(
        r,
        Err(SymxError::Length {
            what: "work vector",
            ..
        })
    ));
    assert_eq!((map.len(), map.is_empty()), (4, false));
}

/// Compiled functions (with their call and table data), maps and tables cross threads.
#[test]
fn compiled_objects_are_send_and_sync() {
    const fn assert_send_sync<T: Send + Sync>() {}
    assert_send_sync::<Function>();
    assert_send_sync::<symx::Map>();
    assert_send_sync::<symx::Interpolant>();
}

/// One map (with its worker threads) shared by several calling threads at once: runs are
/// serialised inside the map and every caller gets the serial results; fewer points than
/// threads and no points at all work too.
#[test]
fn one_parallel_map_serves_concurrent_callers_and_small_sizes() {
    let f = function();
    let n = 300;
    let xs: Vec<f64> = (0..3 * n).map(|i| (i as f64 * 0.11).cos()).collect();
    let ps: Vec<f64> = (0..n).map(|i| i as f64 * 0.01).collect();
    let (mut y_ref, mut z_ref) = (vec![0.0; 3 * n], vec![0.0; n]);
    let mut work = vec![0.0; f.work_size()];
    f.eval_batch(&[&xs, &ps], &mut [&mut y_ref, &mut z_ref], &mut work, n)
        .unwrap();
    let map = f.map(n).parallel(3).unwrap();
    assert_eq!(map.threads(), 3);
    std::thread::scope(|s| {
        for _ in 0..4 {
            s.spawn(|| {
                let (mut y, mut z) = (vec![0.0; 3 * n], vec![0.0; n]);
                let mut work = vec![0.0; map.work_size()];
                for _ in 0..20 {
                    map.eval(&[&xs, &ps], &mut [&mut y, &mut z], &mut work)
                        .unwrap();
                    assert!(y == y_ref && z == z_ref);
                }
            });
        }
    });
    let small = f.map(2).parallel(8).unwrap();
    assert_eq!(small.threads(), 2);
    let (mut y, mut z) = (vec![0.0; 6], vec![0.0; 2]);
    let mut work = vec![0.0; small.work_size()];
    small
        .eval(&[&xs[..6], &ps[..2]], &mut [&mut y, &mut z], &mut work)
        .unwrap();
    assert!(y[..] == y_ref[..6] && z[..] == z_ref[..2]);
    let empty = f.map(0).parallel(4).unwrap();
    let mut work = vec![0.0; empty.work_size()];
    empty
        .eval(&[&[], &[]], &mut [&mut [], &mut []], &mut work)
        .unwrap();
}
