//! The motion pipeline: everything between a drawing request and the step pulses, in the order
//! the data flows through it.
//!
//! A request (a line, arc, ellipse, sine, or a function in the expression language of [`expr`])
//! is stepped by an interpolator ([`interp`], choosing its steps by the [`method`]); the drawing
//! builder ([`drawing`]) checks and builds it into a drawing that a [`job`] carries to the job
//! queue; the [`planner`] times the queued steps (look-ahead, then the step generator), scaled
//! live by the feed and rapid [`overrides`], while the [`supervisor`] decides the run state, the
//! pen at rest and the alarms; the step commands go through the step queue to the pulse engine
//! ([`pulse`]), which emits them on the step timer.
//!
//! request -> interpolator -> drawing builder -> job -> planner (look-ahead, step generator) ->
//! pulse engine.

// Point-by-point interpolators: each curve as a stream of single steps.
pub mod interp;

// The expression language of function curves y = f(x).
pub mod expr;

// The one builder of drawings: a request checked and built for both front ends.
pub mod drawing;

// What the machine is asked to do: jobs and run-time controls.
pub mod job;

// The interpolation method, classic or diagonal (`$202`).
pub mod method;

// Feed and rapid overrides, applied by the planner to queued motion.
pub mod overrides;

// The motion planner: timed step commands from queued steps.
pub mod planner;

// The motion task's decisions: run state, the pen at rest, alarms.
pub mod supervisor;

// The pulse engine: the step timer's work, the only writer of the position.
pub mod pulse;
