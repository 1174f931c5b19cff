//! The node's model loop without DDS (`ros::model::ModelLoop`), on a simulated clock
//! (`use_sim_time`) that the test moves: what the node's subscriptions would feed it, the test
//! pushes into its inbox.

use rotor_twin::ros::model::{Inbox, ModelLoop, NodeClock};
use rotor_twin::ros::NodeParams;
use rotor_twin::rotor::Rotor;
use std::sync::atomic::AtomicU64;
use std::sync::{Arc, Mutex};

/// The model loop of `rotor` with the node's default parameters on simulation time, its inbox
/// and its clock.
pub fn on_sim_time(rotor: Rotor) -> (ModelLoop, Arc<Mutex<Inbox>>, Arc<NodeClock>) {
    let params = NodeParams {
        use_sim_time: true,
        ..NodeParams::default()
    };
    let inbox = Arc::new(Mutex::new(Inbox::default()));
    let clock = Arc::new(NodeClock {
        sim: true,
        ..NodeClock::default()
    });
    let live = (
        Arc::new(Mutex::new(params.clone())),
        Arc::new(AtomicU64::new(0)),
    );
    let model = ModelLoop::new(rotor, params, live, inbox.clone(), clock.clone());
    (model, inbox, clock)
}
