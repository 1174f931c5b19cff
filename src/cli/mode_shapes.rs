//! `rotor-twin modes --shapes-rpm N`: the damped mode shapes at one speed, read along the rotor
//! as rotordynamics codes draw them: at every node the orbit ellipse of the mode (forward and
//! backward circular radii, semi-axes, sense, major-axis direction) and the deflected line at
//! the instant the largest orbit reaches its major axis.
//!
//! A mode's displacement at node n is x(t) = Re(x̂ e^{iωt}), y(t) = Re(ŷ e^{iωt}) (growth left
//! out). As a complex position x + iy = A e^{iωt} + B e^{−iωt} with A = (x̂ + iŷ)/2 (the
//! forward circle, radius |A|) and B = (x̂* + iŷ*)/2 (the backward one, radius |B|); the ellipse
//! has semi-axes |A| + |B| and ||A| − |B||, its major axis at (arg A + arg B)/2, reached at
//! ωt = (arg B − arg A)/2 (Friswell et al., *Dynamics of Rotating Machines*, CUP 2010, §3.5).

use crate::rotor::{damped_mode_shapes, BearingModel, Rotor, StaticSolution, WhirlDirection};
use crate::units::rpm_to_rad_s;
use faer::c64;
use serde::Serialize;

/// The orbit of one node in one mode, normalised so that the largest semi-major axis of the
/// mode is 1.
#[derive(Debug, Clone, Copy, Serialize)]
pub(crate) struct NodeOrbit {
    pub node: usize,
    pub z_m: f64,
    /// Deflection along the reference station's major axis at the instant that station is at
    /// its extreme (signed: a sign change along the rotor is a node of the mode).
    pub deflection: f64,
    pub semi_major: f64,
    pub semi_minor: f64,
    /// Sense of this node's orbit (the mode's overall sense may differ at some nodes).
    pub direction: WhirlDirection,
    /// Direction of the major axis from +x towards +y (deg, 0–180).
    pub major_axis_deg: f64,
    /// Forward phasor A e^{iωt*} at the reference instant t* (re, im), normalised: the orbit is
    /// p(τ) = A' e^{iτ} + B' e^{−iτ} from that instant (x + iy, τ = ω(t − t*)).
    pub forward_phasor: [f64; 2],
    /// Backward phasor B e^{−iωt*} at the reference instant (re, im), normalised.
    pub backward_phasor: [f64; 2],
}

/// One mode at the chosen speed.
#[derive(Debug, Clone, Serialize)]
pub(crate) struct ModeShapeReport {
    pub frequency_hz: f64,
    pub log_dec: f64,
    pub damping_ratio: f64,
    pub direction: WhirlDirection,
    pub nodes: Vec<NodeOrbit>,
}

/// The mode shapes of the report.
#[derive(Debug, Clone, Serialize)]
pub(crate) struct ModeShapes {
    pub speed_rpm: f64,
    /// Eccentricity ratio of each film bearing at its static equilibrium there (0 for others).
    pub eccentricity_ratios: Vec<f64>,
    pub modes: Vec<ModeShapeReport>,
}

/// The `n_modes` lowest damped modes at `speed_rpm`, the film bearings linearised at their
/// static equilibrium under `statics` (as in the Campbell diagram; with `follow`, a step, on the
/// tabulated film with the zone-following slopes, as the diagram of `--zone-following`).
pub(crate) fn mode_shapes(
    rotor: &Rotor,
    statics: &StaticSolution,
    (speed_rpm, follow): (f64, Option<f64>),
    n_modes: usize,
) -> anyhow::Result<ModeShapes> {
    anyhow::ensure!(
        speed_rpm.is_finite() && speed_rpm >= 0.0,
        "invalid --shapes-rpm {speed_rpm}: must be a finite speed, zero or above (rpm)"
    );
    let omega = rpm_to_rad_s(speed_rpm);
    let has_film = rotor
        .bearings
        .iter()
        .any(|b| matches!(b.model, BearingModel::Film(_)));
    anyhow::ensure!(
        omega > 0.0 || !has_film,
        "invalid --shapes-rpm 0: a film bearing carries no static load at rest; give a speed above zero"
    );
    let mut solvers = match follow {
        Some(step) => crate::rotor::BearingSolvers::tabulated(rotor)?.following_zone(step),
        None => crate::rotor::BearingSolvers::new(rotor),
    };
    let (coefs, eps) = solvers.at_speed(rotor, &statics.bearing_loads_n, omega)?;
    let shapes = damped_mode_shapes(rotor, omega, &coefs)?;
    let modes = shapes
        .iter()
        .take(n_modes)
        .map(|m| ModeShapeReport {
            frequency_hz: m.mode.frequency_hz,
            log_dec: m.mode.log_dec,
            damping_ratio: m.mode.damping_ratio,
            direction: m.mode.direction,
            nodes: node_orbits(rotor, &m.shape),
        })
        .collect();
    Ok(ModeShapes {
        speed_rpm,
        eccentricity_ratios: eps,
        modes,
    })
}

/// Forward and backward phasors (A, B) of node `n` (see the module's note).
fn phasors(shape: &[c64], n: usize) -> (c64, c64) {
    let (x, y) = (shape[4 * n], shape[4 * n + 1]);
    let i = c64::new(0.0, 1.0);
    ((x + i * y) * 0.5, (x.conj() + i * y.conj()) * 0.5)
}

/// The orbit of every node of one mode shape, normalised to the largest semi-major axis.
pub(crate) fn node_orbits(rotor: &Rotor, shape: &[c64]) -> Vec<NodeOrbit> {
    let n_nodes = rotor.n_nodes();
    let pairs: Vec<(c64, c64)> = (0..n_nodes).map(|n| phasors(shape, n)).collect();
    let major = |(a, b): (c64, c64)| a.norm() + b.norm();
    let reference = (0..n_nodes)
        .max_by(|&i, &j| major(pairs[i]).total_cmp(&major(pairs[j])))
        .unwrap_or(0);
    let scale = major(pairs[reference]).max(f64::MIN_POSITIVE);
    let (ar, br) = pairs[reference];
    // the instant ωt* the reference reaches its major axis, and that axis' direction β
    let wt = 0.5 * (br.arg() - ar.arg());
    let beta = 0.5 * (ar.arg() + br.arg());
    let turn = c64::new(wt.cos(), wt.sin());
    let back = c64::new(beta.cos(), -beta.sin());
    pairs
        .iter()
        .enumerate()
        .map(|(n, &(a, b))| {
            let (a1, b1) = (a * turn / scale, b * turn.conj() / scale);
            let p = a1 + b1;
            NodeOrbit {
                node: n,
                z_m: rotor.node_z_m[n],
                deflection: (p * back).re,
                semi_major: (a.norm() + b.norm()) / scale,
                semi_minor: (a.norm() - b.norm()).abs() / scale,
                direction: if a.norm() >= b.norm() {
                    WhirlDirection::Forward
                } else {
                    WhirlDirection::Backward
                },
                major_axis_deg: (0.5 * (a.arg() + b.arg())).to_degrees().rem_euclid(180.0),
                forward_phasor: [a1.re, a1.im],
                backward_phasor: [b1.re, b1.im],
            }
        })
        .collect()
}

/// The panels of the mode-shape plot.
pub(crate) fn panels(shapes: &ModeShapes) -> Vec<crate::plot::ShapePanel> {
    shapes
        .modes
        .iter()
        .enumerate()
        .map(|(i, m)| crate::plot::ShapePanel {
            title: format!(
                "mode {}: {:.2} Hz, {}, log dec {:.3}",
                i + 1,
                m.frequency_hz,
                match m.direction {
                    WhirlDirection::Forward => "forward",
                    WhirlDirection::Backward => "backward",
                },
                shown_log_dec(m.log_dec)
            ),
            nodes: m
                .nodes
                .iter()
                .map(|n| crate::plot::ShapeNode {
                    z_m: n.z_m,
                    deflection: n.deflection,
                    semi_major: n.semi_major,
                    forward: n.forward_phasor,
                    backward: n.backward_phasor,
                })
                .collect(),
        })
        .collect()
}

/// The stations whose orbits are drawn: both shaft ends, the bearings, the discs and the probes.
pub(crate) fn stations(rotor: &Rotor) -> Vec<crate::plot::ShapeStation> {
    let last = rotor.n_nodes().saturating_sub(1);
    let station = |name: &str, node: usize, bearing: bool| crate::plot::ShapeStation {
        name: name.to_string(),
        node,
        bearing,
    };
    let mut out: Vec<crate::plot::ShapeStation> = rotor
        .bearings
        .iter()
        .map(|b| station(&b.name, b.node, true))
        .collect();
    out.extend(rotor.discs.iter().map(|d| station(&d.name, d.node, false)));
    out.extend(rotor.probes.iter().map(|p| station(&p.name, p.node, false)));
    for (name, node) in [("end z = 0", 0), ("far end", last)] {
        out.push(station(name, node, false));
    }
    // then every node, unnamed, where there is room
    out.extend((0..=last).map(|n| station("", n, false)));
    // in order of priority: a node is drawn under the first name it has
    let mut seen = Vec::new();
    out.retain(|s| {
        let new = !seen.contains(&s.node);
        seen.push(s.node);
        new
    });
    out
}

/// The shaft as drawn: consecutive elements of equal diameters merged into sections.
fn sections(rotor: &Rotor) -> Vec<crate::plot::SectionGlyph> {
    let mut out: Vec<crate::plot::SectionGlyph> = Vec::new();
    for (e, el) in rotor.elements.iter().enumerate() {
        let (z0, z1) = (rotor.node_z_m[e], rotor.node_z_m[e + 1]);
        match out.last_mut() {
            Some(s)
                if s.outer_diameter_m == el.outer_diameter_m
                    && s.inner_diameter_m == el.inner_diameter_m =>
            {
                s.z1_m = z1
            }
            _ => out.push(crate::plot::SectionGlyph {
                z0_m: z0,
                z1_m: z1,
                outer_diameter_m: el.outer_diameter_m,
                inner_diameter_m: el.inner_diameter_m,
            }),
        }
    }
    out
}

/// Outer diameter of the shaft at `node` (the larger of the elements that meet there, m).
fn shaft_diameter_at(rotor: &Rotor, node: usize) -> f64 {
    let left = node.checked_sub(1).and_then(|e| rotor.elements.get(e));
    let right = rotor.elements.get(node);
    left.into_iter()
        .chain(right)
        .map(|e| e.outer_diameter_m)
        .fold(0.0, f64::max)
}

/// A disc as the uniform annulus on the shaft with its mass and inertias: bore r (the shaft),
/// Ip = m(R² + r²)/2 gives R² = 2Ip/m − r², and Id = Ip/2 + m t²/12 gives t² = (12 Id − 6 Ip)/m
/// (a disc thinner than 0.5 % of the rotor, or with Id ≤ Ip/2, is drawn that thin).
fn disc_glyph(rotor: &Rotor, d: &crate::rotor::Disc) -> crate::plot::DiscGlyph {
    let r = 0.5 * shaft_diameter_at(rotor, d.node);
    let span = rotor.node_z_m.last().copied().unwrap_or(1.0);
    let r_out2 = 2.0 * d.polar_inertia_kg_m2 / d.mass_kg - r * r;
    let t2 = (12.0 * d.diametral_inertia_kg_m2 - 6.0 * d.polar_inertia_kg_m2) / d.mass_kg;
    crate::plot::DiscGlyph {
        name: d.name.clone(),
        z_m: rotor.node_z_m[d.node],
        outer_diameter_m: 2.0 * r_out2.max(1.2 * r * r).sqrt(),
        width_m: t2.max(0.0).sqrt().max(0.005 * span),
    }
}

/// The rotor model as drawn from its machine file.
pub(crate) fn rotor_drawing(rotor: &Rotor) -> crate::plot::RotorDrawing {
    let bearings = rotor
        .bearings
        .iter()
        .map(|b| {
            let (kind, length, dia) = match &b.model {
                BearingModel::Film(f) => (
                    format!(
                        "{} Ø{:.0}×{:.0}",
                        if f.short { "short" } else { "finite" },
                        f.geometry.diameter_m * 1e3,
                        f.geometry.length_m * 1e3
                    ),
                    f.geometry.length_m,
                    f.geometry.diameter_m,
                ),
                BearingModel::Linear(_) => ("linear".to_string(), 0.0, 0.0),
                BearingModel::Rigid => ("rigid".to_string(), 0.0, 0.0),
            };
            crate::plot::BearingGlyph {
                label: format!("{} ({kind})", b.name),
                z_m: rotor.node_z_m[b.node],
                journal_diameter_m: dia.max(shaft_diameter_at(rotor, b.node)),
                pad_length_m: length,
                rigid: matches!(b.model, BearingModel::Rigid),
            }
        })
        .collect();
    crate::plot::RotorDrawing {
        title: format!("Rotor model: {}", rotor.name),
        sections: sections(rotor),
        node_z_m: rotor.node_z_m.clone(),
        discs: rotor.discs.iter().map(|d| disc_glyph(rotor, d)).collect(),
        bearings,
        probes: rotor
            .probes
            .iter()
            .map(|p| {
                (
                    p.name.clone(),
                    rotor.node_z_m[p.node],
                    shaft_diameter_at(rotor, p.node),
                )
            })
            .collect(),
        unbalances: rotor
            .unbalance
            .iter()
            .map(|u| {
                (
                    format!(
                        "{:.0} g·mm at {:.0}°",
                        u.magnitude_kg_m * 1e6,
                        u.phase_rad.to_degrees()
                    ),
                    rotor.node_z_m[u.node],
                    shaft_diameter_at(rotor, u.node),
                )
            })
            .collect(),
    }
}

/// A log decrement as printed to 3 decimals: a round-off −0.0004 is shown as 0.000, not −0.000.
pub(crate) fn shown_log_dec(d: f64) -> f64 {
    if d.abs() < 5e-4 {
        0.0
    } else {
        d
    }
}
