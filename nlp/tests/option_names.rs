//! Options set by name from text (`NamedOptions::set_by_name`), both back ends.
use nlp::{IpmOptions, MuStrategy, NamedOptions, OptionError, SqpOptions};

#[test]
fn sets_numbers_integers_booleans_and_enums() {
    let mut o = IpmOptions::default();
    o.set_by_name(&[
        "tol=1e-10",
        "max_iter = 42",
        "mu_strategy=adaptive",
        "start_with_resto=true",
    ])
    .unwrap();
    assert_eq!(o.tol, 1e-10);
    assert_eq!(o.max_iter, 42);
    assert_eq!(o.mu_strategy, Some(MuStrategy::Adaptive));
    assert!(o.start_with_resto);
    let mut s = SqpOptions::default();
    s.set_by_name(&["max_iter=7"]).unwrap();
    assert_eq!(s.max_iter, 7);
}

#[test]
fn errors_name_the_option_and_leave_the_options_unchanged() {
    let mut o = IpmOptions::default();
    let before = o.clone();
    type Expect = fn(&OptionError) -> bool;
    let cases: [(&str, Expect); 6] = [
        (
            "toll=1",
            |e| matches!(e, OptionError::Unknown { key, valid } if key == "toll" && valid.contains("max_iter")),
        ),
        ("tol", |e| matches!(e, OptionError::Syntax(a) if a == "tol")),
        (
            "max_iter=many",
            |e| matches!(e, OptionError::BadValue { key, .. } if key == "max_iter"),
        ),
        (
            "max_iter=1.5",
            |e| matches!(e, OptionError::BadValue { key, .. } if key == "max_iter"),
        ),
        (
            "mu_strategy=fast",
            |e| matches!(e, OptionError::BadValue { key, .. } if key == "mu_strategy"),
        ),
        ("tol=-1", |e| {
            matches!(e, OptionError::Invalid(_)) && e.to_string().contains("tol")
        }),
    ];
    for (assignment, expected) in cases {
        // The bad assignment comes after a good one: neither is applied.
        let err = o.set_by_name(&["max_iter=5", assignment]).unwrap_err();
        assert!(expected(&err), "{assignment}: {err}");
        assert_eq!(o, before, "{assignment} changed the options");
    }
    // An option of the other back end is unknown here.
    let err = SqpOptions::default()
        .set_by_name(&["mu_strategy=adaptive"])
        .unwrap_err();
    assert!(matches!(err, OptionError::Unknown { .. }), "{err}");
}

/// IPOPT's `recalc_y` is an optional switch (None: on with the limited-memory Hessian,
/// as IPOPT decides); yes/no set it as IPOPT spells it, a non-positive
/// `recalc_y_feas_tol` is refused by name.
#[test]
fn recalc_y_takes_ipopts_words_and_its_tolerance_is_checked() {
    let mut o = IpmOptions::default();
    assert_eq!(o.recalc_y, None);
    o.set_by_name(&["recalc_y=yes"]).unwrap();
    assert_eq!(o.recalc_y, Some(true));
    o.set_by_name(&["recalc_y=no"]).unwrap();
    assert_eq!(o.recalc_y, Some(false));
    assert!(matches!(
        o.set_by_name(&["recalc_y=maybe"]),
        Err(OptionError::BadValue { key, .. }) if key == "recalc_y"
    ));
    let bad = IpmOptions {
        recalc_y_feas_tol: 0.0,
        ..IpmOptions::default()
    };
    let e = bad.validate().unwrap_err().to_string();
    assert!(e.contains("recalc_y_feas_tol"), "{e}");
}

/// `residual_ratio_singular` (IPOPT's name) is optional: None means `residual_ratio_max`;
/// a value below `residual_ratio_max` is refused by name.
#[test]
fn residual_ratio_singular_is_checked_against_residual_ratio_max() {
    let mut o = IpmOptions::default();
    assert_eq!(o.singular_residual_ratio(), o.residual_ratio_max);
    o.set_by_name(&["residual_ratio_singular=1e-5"]).unwrap();
    assert_eq!(o.residual_ratio_singular, Some(1e-5));
    assert_eq!(o.singular_residual_ratio(), 1e-5);
    let bad = IpmOptions {
        residual_ratio_singular: Some(1e-12),
        ..IpmOptions::default()
    };
    let e = bad.validate().unwrap_err().to_string();
    assert!(e.contains("residual_ratio_singular"), "{e}");
}

/// IPOPT's default switch: with `hessian_approximation = limited-memory` the barrier
/// strategy is adaptive unless the user sets `mu_strategy`, which always wins; the
/// quality-function oracle's options are set with IPOPT's names and values.
#[test]
fn limited_memory_defaults_to_adaptive_unless_the_user_chose() {
    use nlp::{MuOracle, QualityFunctionCentrality, QualityFunctionNorm};
    let mut o = IpmOptions::default();
    assert_eq!(o.mu_strategy, None);
    assert_eq!(o.effective_mu_strategy(), MuStrategy::Monotone);
    o.set_by_name(&["hessian_approximation=limited-memory"])
        .unwrap();
    assert_eq!(o.effective_mu_strategy(), MuStrategy::Adaptive);
    o.set_by_name(&["mu_strategy=monotone"]).unwrap();
    assert_eq!(o.effective_mu_strategy(), MuStrategy::Monotone);
    o.set_by_name(&[
        "mu_oracle=quality-function",
        "quality_function_norm_type=max-norm",
        "quality_function_centrality=cubed-reciprocal",
        "quality_function_balancing_term=cubic",
        "quality_function_max_section_steps=12",
        "sigma_max=50",
    ])
    .unwrap();
    assert_eq!(o.mu_oracle, MuOracle::QualityFunction);
    assert_eq!(o.quality_function_norm_type, QualityFunctionNorm::MaxNorm);
    assert_eq!(
        o.quality_function_centrality,
        QualityFunctionCentrality::CubedReciprocal
    );
    assert_eq!(
        (o.quality_function_max_section_steps, o.sigma_max),
        (12, 50.0)
    );
    assert!(o
        .set_by_name(&["quality_function_section_sigma_tol=1"])
        .is_err());
}

/// The quality-function oracle's σ range is checked: σ_min above σ_max is refused by
/// name (the golden-section search would have an empty bracket).
#[test]
fn sigma_min_above_sigma_max_is_refused() {
    let bad = IpmOptions {
        sigma_min: 10.0,
        sigma_max: 1.0,
        ..IpmOptions::default()
    };
    let e = bad.validate().unwrap_err().to_string();
    assert!(e.contains("sigma_min"), "{e}");
    assert!(IpmOptions::default().validate().is_ok());
}
