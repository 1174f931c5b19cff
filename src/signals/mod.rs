//! The plant's own signals, as a rig delivers them (issue 12): the once-per-revolution
//! keyphasor that references the shaft angle ([`keyphasor`]), the 1X phase lag measured from it
//! ([`phase`]), and raw proximity-probe readings along each probe's own axis ([`probes`]).
//! I/O-free: the driver uses them for the node and the replay alike.

pub mod keyphasor;
pub mod phase;
pub mod probes;

pub use keyphasor::{
    KeyphasorEvent, KeyphasorEvents, KeyphasorLock, KeyphasorRefusal, KeyphasorSettings,
    PhaseReference, Unbracketed, KEYPHASOR_JITTER_S, KEYPHASOR_STOP_REVS,
};
pub use phase::{keyphasor_one_x, one_x_vector, OneXVector};
