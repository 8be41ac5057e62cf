//! A closed loop of real-time iterations driven step by step (`Rti::shift`, `prepare`,
//! `feedback`), for tests that inspect each feedback.

use nlp::ocp::{Simulator, Transcription};
use nlp::sqp::rti::Feedback;
use nlp::{Rti, Status};

/// Runs `steps` real-time iterations of `rti` (already initialised) against `plant` from
/// `x_init`: each step applies the plan's first control for `dt`, shifts the plan,
/// prepares and feeds back the new state. Returns each step's applied control and
/// feedback. Panics on an error (a test helper).
pub fn rti_feedbacks(
    tr: &Transcription,
    rti: &mut Rti,
    plant: &mut Simulator,
    (x_init, dt): (&[f64], f64),
    steps: usize,
) -> Vec<(Vec<f64>, Feedback)> {
    let shift = tr.shift_plan().expect("shift plan");
    let u_first = tr
        .problem()
        .variable_indices(&tr.controls().column(0).expect("a control"))
        .expect("control indices");
    let (mut x, mut next) = (x_init.to_vec(), x_init.to_vec());
    (0..steps)
        .map(|_| {
            let u: Vec<f64> = u_first.iter().map(|&k| rti.plan().x[k]).collect();
            plant.step_into(&x, &u, dt, &mut next).expect("plant step");
            std::mem::swap(&mut x, &mut next);
            rti.shift(&shift).expect("shift");
            rti.prepare().expect("prepare");
            (u, rti.feedback(&x).expect("feedback"))
        })
        .collect()
}

/// Asserts that every feedback of `steps` (from [`rti_feedbacks`]) took its step
/// (`RealTimeIterationTaken`) as the prepared step corrected for the measured state
/// (`Feedback::corrected`), with no factorisation and no clarabel fallback.
pub fn assert_every_feedback_corrected(steps: &[(Vec<f64>, Feedback)]) {
    assert!(steps
        .iter()
        .all(|(_, fb)| fb.status == Status::RealTimeIterationTaken));
    let flags: Vec<_> = steps
        .iter()
        .map(|(_, fb)| (fb.corrected, fb.factorizations, fb.fallback))
        .collect();
    assert!(flags.iter().all(|&f| f == (true, 0, false)), "{flags:?}");
}
