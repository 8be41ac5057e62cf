//! Runs the Rust code blocks of docs/solvers.md (the first one is a complete program).

mod example {
    use nlp::{Ipm, IpmOptions, Problem, Relation, Status};

    // Keep in sync with the first code block of docs/solvers.md (checked below).
    pub fn main() -> Result<(), Box<dyn std::error::Error>> {
        let mut pb = Problem::new();
        let x = pb.variable("x", 2);
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
