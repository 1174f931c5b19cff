//! rotor-twin: a live digital twin of a rotor on fluid-film bearings.
//!
//! Built after Kiciński & Żywica, *Modelling fluid-film bearings in high-speed rotating machinery
//! considering the prehistory of dynamic phenomena*, Sci. Rep. 15:43354 (2025) ("the seed").
//! SI units everywhere inside; names carry the unit where it is not SI.

pub mod bag;
pub mod calibrate;
pub mod cli;
pub mod driver;
pub mod dynamics;
pub mod film;
pub mod forecast;
pub mod messages;
pub mod monitor;
pub mod plant;
pub mod plot;
pub mod record;
pub mod replay;
pub mod ros;
pub mod rotor;
pub mod session;
pub mod signals;
pub mod sweep;
pub mod topics;
pub mod transient;
pub mod units;
pub mod viewer;
