"""IPOPT's adaptive mu (exact Hessian) on the Hock-Schittkowski suite with its default
quality-function oracle and with the probing oracle; one JSON line per problem and
oracle (field "oracle": "qf" or "probing"). Reference for docs/performance.md
("Limited-memory mode: IPOPT's adaptive mu").

Usage (from the repository root):
    python3 benches/reference/hs_exact_adaptive_ipopt.py 2>/dev/null | grep '^{' \
        > benches/reference/results/hs_exact_adaptive_ipopt.jsonl
symnlp's side:
    OPT=hessian_approximation=exact,mu_strategy=adaptive cargo test --release \
        -p nlp --test lbfgs_hs -- --ignored --nocapture hs_lbfgs_summary
(add ,mu_oracle=probing for the probing oracle).
"""
import sys, json
sys.path.insert(0, 'benches/reference')
import hs_casadi
for n in sorted(hs_casadi.PROBLEMS):
    for tag, o in [('qf', {'ipopt.mu_strategy':'adaptive'}), ('probing', {'ipopt.mu_strategy':'adaptive','ipopt.mu_oracle':'probing'})]:
        r = hs_casadi.solve(n, o); r['oracle']=tag
        print(json.dumps(r), flush=True)
