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

/// `rotor-twin param`: a running node's parameters, through its ROS 2 parameter services (run
/// it in the node's network namespace).
#[derive(Debug, Clone, Args)]
pub struct ParamArgs {
    /// The node.
    #[arg(long, default_value = "/rotor_twin")]
    node: String,
    /// Seconds to wait for the node's answer.
    #[arg(long, default_value_t = 10.0)]
    timeout: f64,
    #[command(subcommand)]
    call: ParamCommand,
}

#[derive(Debug, Clone, clap::Subcommand)]
enum ParamCommand {
    /// Print parameters' values.
    Get {
        /// Parameter names.
        #[arg(required = true)]
        names: Vec<String>,
    },
    /// Set parameters: NAME:=VALUE (a start-only parameter is refused with the node's reason).
    Set {
        /// NAME:=VALUE assignments.
        #[arg(required = true, value_parser = parse_assignment)]
        assignments: Vec<(String, String)>,
    },
}

fn parse_assignment(s: &str) -> Result<(String, String), String> {
    let (name, value) = s
        .split_once(":=")
        .ok_or_else(|| format!("'{s}': expected NAME:=VALUE"))?;
    if name.is_empty() {
        return Err(format!("'{s}': missing parameter name"));
    }
    Ok((name.into(), value.into()))
}

pub(crate) fn run_param(args: ParamArgs) -> anyhow::Result<()> {
    anyhow::ensure!(
        args.timeout.is_finite() && args.timeout > 0.0,
        "--timeout {}: must be positive (s)",
        args.timeout
    );
    let call = match args.call {
        ParamCommand::Get { names } => crate::ros::ParamCall::Get(names),
        ParamCommand::Set { assignments } => crate::ros::ParamCall::Set(assignments),
    };
    crate::ros::param_call(
        &args.node,
        call,
        std::time::Duration::from_secs_f64(args.timeout),
    )
}
