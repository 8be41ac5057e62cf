//! Quadruped gap-crossing planner.
