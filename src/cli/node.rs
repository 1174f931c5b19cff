//! `rotor-twin node`: the live ROS 2 node.

use clap::Args;
use std::path::PathBuf;

/// The live ROS 2 node (run it inside a private network namespace on shared machines).
#[derive(Debug, Clone, Args)]
pub struct NodeArgs {
    /// Machine description (YAML); the built-in ORC microturbine if absent.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Record every input and output into this new bag directory (rosbag2 MCAP).
    #[arg(long)]
    record: Option<PathBuf>,
    /// ROS arguments: -p name:=value, --params-file F.yaml, -r from:=to.
    #[arg(long = "ros-args", num_args = 0.., allow_hyphen_values = true)]
    ros_args: Vec<String>,
}

pub(crate) fn run(args: NodeArgs) -> anyhow::Result<()> {
    crate::ros::run(crate::ros::NodeSetup {
        config: args.config,
        record: args.record,
        ros_args: args.ros_args,
    })
}
