//! Solves the crawl formulation (as `export` builds it) with symnlp's IPM and prints the
//! iteration table and the time split, for profiling.
//!
//! ```text
//! cargo run --release -p gap_crossing --example crawl_profile -- \
//!     --set n_step=60 --set gap.depth=0 [--repeat 5] [--log]
//! ```
use gap_crossing::export;
use gap_crossing::solve::status_name;
use nlp::{Ipm, IpmOptions};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut overrides: Vec<String> = Vec::new();
    let mut repeat = 1usize;
    let mut log = false;
    let mut opts_kv: Vec<(String, String)> = Vec::new();
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--set" => overrides.push(args.next().ok_or("--set needs KEY=VALUE")?),
            "--repeat" => repeat = args.next().ok_or("--repeat needs a number")?.parse()?,
            "--log" => log = true,
            "--opt" => {
                let kv = args.next().ok_or("--opt needs KEY=VALUE")?;
                let (k, v) = kv.split_once('=').ok_or("--opt needs KEY=VALUE")?;
                opts_kv.push((k.to_string(), v.to_string()));
            }
            other => return Err(format!("unknown argument {other}").into()),
        }
    }
    let mut s = gap_crossing::scenario::Scenario::default();
    s.apply_overrides(&overrides)?;
    s.validate()?;
    let mut times = Vec::new();
    for r in 0..repeat.max(1) {
        let (model, mut compiled) = export::crawl_model(&s)?;
        let mut opts = IpmOptions {
            common: nlp::CommonOptions {
                print_level: if log && r == 0 { 5 } else { 0 },
                ..Default::default()
            },
            ..IpmOptions::default()
        };
        for (k, v) in &opts_kv {
            match k.as_str() {
                "mu_strategy" => {
                    opts.mu_strategy = Some(match v.as_str() {
                        "adaptive" => nlp::MuStrategy::Adaptive,
                        _ => nlp::MuStrategy::Monotone,
                    })
                }
                "perturbation_skip_zero_after" => opts.perturbation_skip_zero_after = v.parse()?,
                "perturb_dec_fact" => opts.perturb_dec_fact = v.parse()?,
                "perturb_inc_fact" => opts.perturb_inc_fact = v.parse()?,
                "mu_init" => opts.mu_init = v.parse()?,
                "max_soc" => opts.max_soc = v.parse()?,
                "min_refinement_steps" => opts.min_refinement_steps = v.parse()?,
                "first_hessian_perturbation" => opts.first_hessian_perturbation = v.parse()?,
                "bound_push" => opts.bound_push = v.parse()?,
                "bound_frac" => opts.bound_frac = v.parse()?,
                "mu_linear_decrease_factor" => opts.mu_linear_decrease_factor = v.parse()?,
                "barrier_tol_factor" => opts.barrier_tol_factor = v.parse()?,
                "nlp_scaling_min_gradient" => opts.nlp_scaling_min_gradient = v.parse()?,
                other => return Err(format!("unknown option {other}").into()),
            }
        }
        let t = Instant::now();
        let sol = Ipm::new(opts).solve(&mut compiled)?;
        let dt = t.elapsed().as_secs_f64();
        drop(model);
        let st = &sol.stats;
        println!(
            "{} iter {} f {:.12e} solve {:.4} s: factor {:.4} eval {:.4} other {:.4}; \
             factorizations {}, evals f {} grad {} g {} jac {} hess {}",
            status_name(sol.status),
            st.iterations,
            sol.objective,
            dt,
            st.factor_seconds,
            st.eval_seconds,
            st.other_seconds,
            st.n_factorizations,
            st.n_eval_f,
            st.n_eval_grad_f,
            st.n_eval_g,
            st.n_eval_jac_g,
            st.n_eval_hess_l
        );
        times.push(dt);
    }
    times.sort_by(f64::total_cmp);
    println!("median solve {:.4} s", times[times.len() / 2]);
    Ok(())
}
