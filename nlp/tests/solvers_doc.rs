//! Runs the Rust code blocks of docs/solvers.md (the first one is a complete program).

mod example {
    use nlp::{Ipm, IpmOptions, Problem, Relation, Status};

    // Keep in sync with the first code block of docs/solvers.md (checked below).
    pub fn main() -> Result<(), Box<dyn std::error::Error>> {
        let mut pb = Problem::new();
        let x = pb.variable("x", 2)?;
        pb.set_initial(&x, &[-1.2, 1.0])?;
        // Rosenbrock on the disc x₀² + x₁² ≤ 1.5.
        pb.minimize(100.0 * (x[1] - x[0].sq()).sq() + (1.0 - x[0]).sq());
        pb.subject_to((x[0].sq() + x[1].sq()).le(1.5))?;
        let mut compiled = pb.compile()?; // derivatives and sparsity, once
        let solver = Ipm::new(IpmOptions::default());
        let sol = solver.solve(&mut compiled)?;
        assert_eq!(sol.status, Status::SolveSucceeded);
        println!("x = {:?}, f = {}", sol.x, sol.objective);

        // Warm start from the previous solution (primal and dual), e.g. after a parameter change.
        let again = solver.solve_warm(&mut compiled, &sol)?;
        assert!(again.stats.iterations <= sol.stats.iterations);
        Ok(())
    }
}

mod callback_example {
    // Keep in sync with the code block of docs/solvers.md, section 10 (checked below).
    use nlp::{Ipm, IterationView, Problem, Relation, Status};
    use std::ops::ControlFlow;

    pub fn watch() -> Result<(), Box<dyn std::error::Error>> {
        let mut pb = Problem::new();
        let x = pb.variable("x", 2)?;
        pb.set_initial(&x, &[-1.2, 1.0])?;
        pb.minimize(100.0 * (x[1] - x[0].sq()).sq() + (1.0 - x[0]).sq());
        pb.subject_to((x[0].sq() + x[1].sq()).le(1.5))?;
        let mut compiled = pb.compile()?;
        let mut path: Vec<Vec<f64>> = Vec::new();
        // One line per iteration; stop early once x is feasible and x₀ > 0.9.
        let sol = Ipm::default().solve_with_callback(&mut compiled, |v: &IterationView<'_>| {
            let r = v.record();
            let mark = if v.in_restoration() { 'r' } else { ' ' };
            println!(
                "{:3}{mark} f = {:.6e}, inf_pr = {:.1e}, x = {:?}",
                r.iter,
                r.objective,
                r.inf_pr,
                v.x()
            );
            path.push(v.x().to_vec());
            if r.inf_pr < 1e-6 && v.x()[0] > 0.9 {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        })?;
        assert_eq!(sol.status, Status::UserRequestedStop);
        assert_eq!(path.len(), sol.stats.iterations + 1);
        assert_eq!(path.last(), Some(&sol.x));
        Ok(())
    }
}

/// The lines of the first ```rust block after `after` in docs/solvers.md.
fn doc_block(after: &str) -> Vec<&'static str> {
    let doc = include_str!("../../docs/solvers.md");
    let from = doc.find(after).unwrap();
    let start = from + doc[from..].find("```rust\n").unwrap() + 8;
    let end = start + doc[start..].find("```").unwrap();
    doc[start..end]
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect()
}

#[test]
fn solvers_md_callback_example_runs() {
    callback_example::watch().unwrap();
}

#[test]
fn solvers_md_callback_example_is_the_one_tested_here() {
    let this = include_str!("solvers_doc.rs");
    for line in doc_block("## 10. ") {
        assert!(
            this.contains(line),
            "docs/solvers.md section 10 line not in the test: {line}"
        );
    }
}

#[test]
fn solvers_md_example_runs() {
    example::main().unwrap();
}

#[test]
fn solvers_md_example_is_the_one_tested_here() {
    let doc = include_str!("../../docs/solvers.md");
    let start = doc.find("```rust\n").unwrap() + 8;
    let end = start + doc[start..].find("```").unwrap();
    let this = include_str!("solvers_doc.rs");
    for line in doc[start..end]
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
    {
        assert!(
            this.contains(line),
            "docs/solvers.md line not in the test: {line}"
        );
    }
}

/// docs/solvers.md section 5: `solve_warm_into` in a loop (each line of the doc's block
/// is checked to be here).
mod warm_into_example {
    #[test]
    fn solvers_md_warm_into_example_runs() {
        use nlp::{Ipm, Problem, Solution};

        let mut pb = Problem::new();
        let x = pb.variable("x", 2).unwrap();
        let p = pb.parameter("p", 1).unwrap();
        pb.set_value(&p, &[0.0]).unwrap();
        pb.minimize((x[0] - p[0]).sq() + (x[1] - 2.0).sq());
        let mut nlp = pb.compile().unwrap();
        let ipm = Ipm::default();
        let mut last: Solution = ipm.solve(&mut nlp).unwrap();
        let mut next = last.clone(); // any solution: its vectors are reused
        for step in 1..5 {
            nlp.set_value("p", &[0.1 * step as f64]).unwrap();
            ipm.solve_warm_into(&mut nlp, &last, &mut next).unwrap();
            std::mem::swap(&mut last, &mut next); // `last` is this step's solution
        }
        assert!((last.x[0] - 0.4).abs() < 1e-6);
        assert!(last.status.is_success() && next.status.is_success());
    }

    #[test]
    fn solvers_md_warm_into_example_is_the_one_tested_here() {
        let this = include_str!("solvers_doc.rs");
        for line in super::doc_block("## 5. ") {
            assert!(
                this.contains(line),
                "docs/solvers.md section 5 line not in the test: {line}"
            );
        }
    }
}

/// docs/solvers.md section 7, "Kept between solves": one `Sqp` along a sequence (each
/// line of the doc's block is checked to be here).
mod sqp_kept_example {
    #[test]
    fn solvers_md_sqp_kept_example_runs() {
        use nlp::{Problem, Relation, Sqp};
        let mut pb = Problem::new();
        let x = pb.variable("x", 2).unwrap();
        let p = pb.scalar_parameter("p").unwrap();
        pb.minimize((x[0] - p).sq() + (x[1] - 1.0).sq());
        pb.subject_to((x[0] + x[1]).le(1.5)).unwrap();
        pb.set_value(&[p], &[0.0]).unwrap();
        let mut c = pb.compile().unwrap();
        let sqp = Sqp::default(); // not `Sqp { options }`: the struct has a private field
        let mut sol = sqp.solve(&mut c).unwrap();
        for k in 1..4 {
            c.set_value(&[p], &[0.1 * k as f64]).unwrap();
            sol = sqp.solve_warm(&mut c, &sol).unwrap(); // reuses the KKT analysis and QP layout
        }
        assert!(sol.status.is_success());
        // p = 0.3: x = (0.3, 1) is feasible (1.3 ≤ 1.5), the unconstrained minimiser.
        assert!((sol.x[0] - 0.3).abs() < 1e-8 && (sol.x[1] - 1.0).abs() < 1e-8);
    }

    #[test]
    fn solvers_md_sqp_kept_example_is_the_one_tested_here() {
        let this = include_str!("solvers_doc.rs");
        for line in super::doc_block("*Kept between solves*") {
            assert!(
                this.contains(line),
                "docs/solvers.md section 7 line not in the test: {line}"
            );
        }
    }
}
