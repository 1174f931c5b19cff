//! The node's parameters as rclcpp's `NodeParameters` keeps them, and its six parameter services
//! (rcl_interfaces: get, get types, set, set atomically, list, describe), served here instead of
//! by ros2-client's `Spinner`. The spinner also creates a reader of `builtin_interfaces/msg/Time`
//! on `/clock`, beside the node's own `rosgraph_msgs/msg/Clock` reader: /clock then has two types
//! in the graph and `ros2 bag record` refuses it (issue 13). Serving the services ourselves removes
//! that reader and lets `describe_parameters` answer with the descriptors of
//! [`super::params::PARAMETER_DOCS`].
//!
//! Values live in [`ParameterStore`], not in ros2-client's store: that one publishes one
//! `/parameter_events` message per value, stamped with a simulation time only its Spinner keeps
//! (0 here under `use_sim_time`). Ours publishes as rclcpp does
//! (rclcpp/src/rclcpp/node_interfaces/node_parameters.cpp): one event per declared parameter at
//! start (`new_parameters`), one per atomic set with all its values (`changed_parameters`), a plain
//! set of N values as N atomic sets of one; `node` = the fully qualified name, stamp = the node's
//! clock (the /clock value under `use_sim_time`, like every other stamp of the node), QoS
//! rmw_qos_profile_parameter_events (reliable, volatile, keep last 1000). ros2-client's own
//! /parameter_events writer (made by its `Node::new`, no option omits it) stays in the graph but
//! never writes: nothing is set in its store.

use super::model::{LiveParams, NodeClock};
use super::params::{parameter_doc, ParamDoc};
use futures::StreamExt;
use ros2_client::builtin_interfaces::Time;
use ros2_client::parameters::raw;
use ros2_client::qos::{Durability, History};
use ros2_client::rcl_interfaces::{
    DescribeParametersRequest, DescribeParametersResponse, GetParameterTypesRequest,
    GetParameterTypesResponse, GetParametersRequest, GetParametersResponse, ListParametersRequest,
    ListParametersResponse, ListParametersResult, SetParametersAtomicallyResponse,
    SetParametersRequest, SetParametersResponse,
};
use ros2_client::{
    Message, MessageTypeName, Name, Node, Parameter, ParameterValue, Publisher, QosProfile, Server,
    ServiceMapping, ServiceTypeName,
};
use std::sync::atomic::Ordering;
use std::sync::{Arc, Mutex};

/// rmw_qos_profile_parameter_events (rmw/qos_profiles.h): reliable, volatile, keep last 1000.
const EVENTS_DEPTH: usize = 1000;

/// The node's parameter values in declaration order, the model thread's copy they are handed to,
/// and the writer of `/parameter_events`.
pub struct ParameterStore {
    values: Mutex<Vec<(String, ParameterValue)>>,
    live: LiveParams,
    events: Publisher<raw::ParameterEvent>,
    fqn: String,
    clock: Arc<NodeClock>,
}

impl ParameterStore {
    /// Declares `declared` (name, initial value) on node `fqn` and publishes one event per
    /// parameter with it in `new_parameters`, as rclcpp's `declare_parameter` does.
    pub fn declare(
        node: &mut Node,
        fqn: &str,
        declared: Vec<(&str, ParameterValue)>,
        live: LiveParams,
        clock: Arc<NodeClock>,
    ) -> anyhow::Result<Self> {
        let qos = QosProfile::publisher_default()
            .durability(Durability::Volatile)
            .history(History::KeepLast {
                depth: EVENTS_DEPTH,
            });
        let name = Name::new("/", "parameter_events").map_err(|e| anyhow::anyhow!("{e:?}"))?;
        let topic = node
            .create_topic(
                &name,
                MessageTypeName::new("rcl_interfaces", "ParameterEvent"),
                &qos,
            )
            .map_err(|e| anyhow::anyhow!("topic /parameter_events: {e:?}"))?;
        let events = node
            .create_publisher(&topic, Some(qos))
            .map_err(|e| anyhow::anyhow!("publisher /parameter_events: {e:?}"))?;
        let store = Self {
            values: Mutex::new(vec![]),
            live,
            events,
            fqn: fqn.to_string(),
            clock,
        };
        for (name, value) in declared {
            let p = Parameter {
                name: name.to_string(),
                value,
            };
            store.lock().push((p.name.clone(), p.value.clone()));
            store.publish(store.event(vec![p], vec![]));
        }
        Ok(store)
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Vec<(String, ParameterValue)>> {
        self.values.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The value of `name`, if declared.
    pub fn get(&self, name: &str) -> Option<ParameterValue> {
        self.lock()
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.clone())
    }

    /// The declared names in declaration order.
    pub fn names(&self) -> Vec<String> {
        self.lock().iter().map(|(n, _)| n.clone()).collect()
    }

    /// SetParametersAtomically: every value tried on a copy of the parameters first; all are set
    /// (and published as ONE event) only if all pass, else none.
    pub fn set_atomically(&self, params: Vec<Parameter>) -> raw::SetParametersResult {
        let mut values = self.lock();
        let mut live = self.live.0.lock().unwrap_or_else(|e| e.into_inner());
        let mut trial = live.clone();
        for p in &params {
            if let Err(reason) = check_type(current(&values, &p.name), p)
                .and_then(|text| trial.set_at_runtime(&p.name, &text))
            {
                return refused(reason);
            }
        }
        *live = trial;
        self.live.1.fetch_add(1, Ordering::SeqCst);
        drop(live);
        for p in &params {
            if let Some(slot) = values.iter_mut().find(|(n, _)| *n == p.name) {
                slot.1 = p.value.clone();
            }
        }
        drop(values);
        self.publish(self.event(vec![], params));
        raw::SetParametersResult {
            successful: true,
            reason: String::new(),
        }
    }

    /// SetParameters as rclcpp answers it: each value an atomic set of its own (one event each).
    pub fn set_each(&self, params: Vec<Parameter>) -> Vec<raw::SetParametersResult> {
        params
            .into_iter()
            .map(|p| self.set_atomically(vec![p]))
            .collect()
    }

    /// An event of this node stamped with the node's clock now (0 before the first /clock under
    /// `use_sim_time`, as rclcpp's ROS time reads before any /clock).
    pub fn event(&self, new: Vec<Parameter>, changed: Vec<Parameter>) -> raw::ParameterEvent {
        parameter_event(&self.fqn, self.clock.now_ns().unwrap_or(0), new, changed)
    }

    fn publish(&self, event: raw::ParameterEvent) {
        if let Err(e) = self.events.publish(event) {
            super::log::warn(&format!("/parameter_events not published: {e:?}"));
        }
    }
}

/// A ParameterEvent of node `fqn` at `stamp_ns` (ns since the epoch).
pub fn parameter_event(
    fqn: &str,
    stamp_ns: i64,
    new: Vec<Parameter>,
    changed: Vec<Parameter>,
) -> raw::ParameterEvent {
    raw::ParameterEvent {
        stamp: Time::from_nanos(stamp_ns),
        node: fqn.to_string(),
        new_parameters: new.into_iter().map(raw::Parameter::from).collect(),
        changed_parameters: changed.into_iter().map(raw::Parameter::from).collect(),
        deleted_parameters: vec![],
    }
}

fn current<'a>(values: &'a [(String, ParameterValue)], name: &str) -> Option<&'a ParameterValue> {
    values.iter().find(|(n, _)| n == name).map(|(_, v)| v)
}

/// The six servers, named `<node>/get_parameters` etc. as rclcpp names them.
pub struct ParameterServices {
    get: Server<GetParametersRequest, GetParametersResponse>,
    get_types: Server<GetParameterTypesRequest, GetParameterTypesResponse>,
    set: Server<SetParametersRequest, SetParametersResponse>,
    // SetParametersAtomically's request has the same layout as SetParameters' (Parameter[])
    set_atomically: Server<SetParametersRequest, SetParametersAtomicallyResponse>,
    list: Server<ListParametersRequest, ListParametersResponse>,
    describe: Server<DescribeParametersRequest, DescribeParametersResponse>,
    /// The values the services read and set.
    store: ParameterStore,
}

fn server<Req, Resp>(
    node: &mut Node,
    fqn: &str,
    service: &str,
    type_name: &str,
) -> anyhow::Result<Server<Req, Resp>>
where
    Req: Message + Clone + 'static,
    Resp: Message + 'static,
{
    // rmw_qos_profile_services_default: reliable, volatile, keep last 10
    let qos = QosProfile::publisher_default().history(History::KeepLast { depth: 10 });
    let name = Name::new(fqn, service).map_err(|e| anyhow::anyhow!("{fqn}/{service}: {e:?}"))?;
    node.create_server(
        ServiceMapping::Enhanced,
        &name,
        &ServiceTypeName::new("rcl_interfaces", type_name),
        qos.clone(),
        qos,
    )
    .map_err(|e| anyhow::anyhow!("parameter service {fqn}/{service}: {e:?}"))
}

impl ParameterServices {
    /// Creates the servers of node `fqn` (its fully qualified name).
    pub fn create(node: &mut Node, fqn: &str, store: ParameterStore) -> anyhow::Result<Self> {
        Ok(Self {
            get: server(node, fqn, "get_parameters", "GetParameters")?,
            get_types: server(node, fqn, "get_parameter_types", "GetParameterTypes")?,
            set: server(node, fqn, "set_parameters", "SetParameters")?,
            set_atomically: server(
                node,
                fqn,
                "set_parameters_atomically",
                "SetParametersAtomically",
            )?,
            list: server(node, fqn, "list_parameters", "ListParameters")?,
            describe: server(node, fqn, "describe_parameters", "DescribeParameters")?,
            store,
        })
    }

    /// Answers requests until the future is dropped. A request that cannot be read or answered
    /// is counted out with a log line; the services carry on.
    pub async fn serve(&self) {
        let mut get = self.get.receive_request_stream();
        let mut get_types = self.get_types.receive_request_stream();
        let mut set = self.set.receive_request_stream();
        let mut set_atomically = self.set_atomically.receive_request_stream();
        let mut list = self.list.receive_request_stream();
        let mut describe = self.describe.receive_request_stream();
        loop {
            let sent = futures::select! {
                r = get.select_next_some() => match r {
                    Ok((id, req)) => self.get.async_send_response(id, GetParametersResponse {
                        values: req.names.iter().map(|n| self.value_of(n)).collect(),
                    }).await,
                    Err(e) => { bad_request("get_parameters", &e); continue }
                },
                r = get_types.select_next_some() => match r {
                    Ok((id, req)) => self.get_types.async_send_response(id, GetParameterTypesResponse {
                        values: req.names.iter().map(|n| self.value_of(n).ptype).collect(),
                    }).await,
                    Err(e) => { bad_request("get_parameter_types", &e); continue }
                },
                r = set.select_next_some() => match r {
                    Ok((id, req)) => self.set.async_send_response(id, SetParametersResponse {
                        results: self.store.set_each(req.parameter.into_iter().map(Parameter::from).collect()),
                    }).await,
                    Err(e) => { bad_request("set_parameters", &e); continue }
                },
                r = set_atomically.select_next_some() => match r {
                    Ok((id, req)) => self.set_atomically.async_send_response(id, SetParametersAtomicallyResponse {
                        result: self.store.set_atomically(req.parameter.into_iter().map(Parameter::from).collect()),
                    }).await,
                    Err(e) => { bad_request("set_parameters_atomically", &e); continue }
                },
                r = list.select_next_some() => match r {
                    Ok((id, req)) => self.list.async_send_response(id, ListParametersResponse {
                        result: list_names(&self.store.names(), &req.prefixes, req.depth),
                    }).await,
                    Err(e) => { bad_request("list_parameters", &e); continue }
                },
                r = describe.select_next_some() => match r {
                    Ok((id, req)) => self.describe.async_send_response(id, DescribeParametersResponse {
                        values: req.names.iter().map(|n| descriptor(n, &self.value_of(n))).collect(),
                    }).await,
                    Err(e) => { bad_request("describe_parameters", &e); continue }
                },
            };
            if let Err(e) = sent {
                super::log::warn(&format!("a parameter service could not answer: {e:?}"));
            }
        }
    }

    /// The value of `name` on the wire; NOT_SET for an unknown name (as rclcpp answers).
    fn value_of(&self, name: &str) -> raw::ParameterValue {
        self.store
            .get(name)
            .unwrap_or(ParameterValue::NotSet)
            .into()
    }
}

fn bad_request(service: &str, e: &dyn std::fmt::Debug) {
    super::log::warn(&format!(
        "parameter service {service}: unreadable request refused: {e:?}"
    ));
}

fn refused(reason: String) -> raw::SetParametersResult {
    raw::SetParametersResult {
        successful: false,
        reason,
    }
}

/// The value as the text [`super::params::NodeParams::set`] reads, if `p` is declared with the same type
/// (rclcpp refuses a change of type unless the descriptor allows dynamic typing, which none of
/// ours does).
fn check_type(current: Option<&ParameterValue>, p: &Parameter) -> Result<String, String> {
    let current = current.ok_or_else(|| format!("parameter '{}' is not declared", p.name))?;
    if current.to_parameter_type() as u8 != p.value.to_parameter_type() as u8 {
        return Err(format!(
            "parameter {} is of type {:?}, not {:?} (write 50.0, not 50, for a double)",
            p.name,
            current.to_parameter_type(),
            p.value.to_parameter_type()
        ));
    }
    super::node::parameter_text(&p.value)
        .ok_or_else(|| format!("parameter {}: unsupported type", p.name))
}

/// The descriptor of `name` with its current value (NOT_SET type for an unknown name).
pub fn descriptor(name: &str, value: &raw::ParameterValue) -> raw::ParameterDescriptor {
    let doc = parameter_doc(name);
    let (integer_range, floating_point_range) = match doc.and_then(|d| d.range) {
        Some((from, to)) if value.ptype == raw::ParameterType::INTEGER => (
            vec![raw::IntegerRange {
                from_value: from as i64,
                to_value: to as i64,
                step: 1,
            }],
            vec![],
        ),
        Some((from, to)) if value.ptype == raw::ParameterType::DOUBLE => (
            vec![],
            vec![raw::FloatingPointRange {
                from_value: from,
                to_value: to,
                step: 0.0,
            }],
        ),
        _ => (vec![], vec![]),
    };
    raw::ParameterDescriptor {
        name: name.to_string(),
        r#type: value.ptype,
        description: doc.map_or("", |d| d.description).to_string(),
        additional_constraints: doc.map_or("", |d| d.constraints).to_string(),
        read_only: doc.is_some_and(ParamDoc::read_only),
        dynamic_typing: false,
        floating_point_range,
        integer_range,
    }
}

/// ListParameters as rclcpp answers it: with no prefixes, the names with fewer than `depth`
/// dots (0: any depth); else the names equal to a prefix or below `prefix.` within `depth`
/// further levels. `prefixes` in the answer are the listed names' namespaces.
pub fn list_names(names: &[String], prefixes: &[String], depth: u64) -> ListParametersResult {
    let levels = |s: &str| s.matches('.').count() as u64;
    let shallow = |dots: u64| depth == 0 || dots < depth;
    let mut result = ListParametersResult {
        names: vec![],
        prefixes: vec![],
    };
    for name in names {
        let listed = if prefixes.is_empty() {
            shallow(levels(name))
        } else {
            prefixes.iter().any(|p| {
                name == p
                    || name
                        .strip_prefix(p.as_str())
                        .and_then(|rest| rest.strip_prefix('.'))
                        .is_some_and(|rest| shallow(levels(rest)))
            })
        };
        if listed {
            result.names.push(name.clone());
            if let Some((ns, _)) = name.rsplit_once('.') {
                if !result.prefixes.iter().any(|p| p == ns) {
                    result.prefixes.push(ns.to_string());
                }
            }
        }
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(v: &[&str]) -> Vec<String> {
        v.iter().map(|s| s.to_string()).collect()
    }

    /// rclcpp's ListParameters (rclcpp/src/rclcpp/node_interfaces/node_parameters.cpp,
    /// `list_parameters`): depth counts the dots below the prefix; 0 is unlimited.
    #[test]
    fn list_follows_rclcpp() {
        let all = names(&["a", "b.c", "b.d.e", "bx"]);
        assert_eq!(list_names(&all, &[], 0).names, all);
        assert_eq!(list_names(&all, &[], 1).names, names(&["a", "bx"]));
        assert_eq!(list_names(&all, &[], 2).names, names(&["a", "b.c", "bx"]));
        let under_b = list_names(&all, &names(&["b"]), 1);
        assert_eq!(under_b.names, names(&["b.c"]));
        assert_eq!(under_b.prefixes, names(&["b"]));
        assert_eq!(
            list_names(&all, &names(&["b"]), 0).names,
            names(&["b.c", "b.d.e"])
        );
    }

    #[test]
    fn descriptors_carry_ranges_and_read_only() {
        let d = descriptor("steps_per_rev", &ParameterValue::Integer(64).into());
        assert_eq!(d.r#type, raw::ParameterType::INTEGER);
        assert_eq!(
            (d.integer_range[0].from_value, d.integer_range[0].to_value),
            (16, 4096)
        );
        assert!(d.read_only);
        let d = descriptor("state_rate_hz", &ParameterValue::Double(200.0).into());
        assert!(!d.read_only && d.floating_point_range.is_empty());
        assert!(d.description.contains("Hz"));
        let d = descriptor("nope", &ParameterValue::NotSet.into());
        assert_eq!(d.r#type, raw::ParameterType::NOT_SET);
    }
}
