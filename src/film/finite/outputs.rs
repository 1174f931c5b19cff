//! What a converged finite-film solution reports: force, peak pressure, the pressure-zone
//! boundaries ζ1 and ζ2, friction and flows.

use super::FiniteFilm;
use crate::film::{wrap_angle_rad, FilmResult};

impl FiniteFilm {
    /// Every reported quantity of the last converged solve at speed `speed_rad_s` (rad/s).
    pub(super) fn outputs(&self, speed_rad_s: f64) -> FilmResult {
        let force_n = self.force_from(|k| self.pi[k]);
        let (max_pressure_pa, max_pressure_angle_rad) = self.peak_pressure();
        let zone = self.midplane_zone();
        let (film_start_rad, film_end_rad) = match zone {
            Some((s, e)) => (self.zone_start_angle(s), self.zone_end_angle(e)),
            None => (0.0, 0.0),
        };
        let friction_torque_n_m = self.friction_torque(speed_rad_s);
        FilmResult {
            force_n,
            max_pressure_pa,
            max_pressure_angle_rad,
            film_start_rad,
            film_end_rad,
            friction_torque_n_m,
            power_loss_w: friction_torque_n_m * speed_rad_s,
            side_flow_m3_s: self.side_flow(),
            inflow_m3_s: zone.map_or(0.0, |(s, _)| self.inflow(s, speed_rad_s)),
        }
    }

    /// Largest pressure (Pa) and its angle (rad), refined by a parabola through the peak node
    /// and its two neighbours around the circumference.
    fn peak_pressure(&self) -> (f64, f64) {
        let (nt, nz) = (self.grid.n_theta, self.grid.n_z);
        let best = self.pi.iter().copied().fold(0.0, f64::max);
        if best <= 0.0 {
            return (0.0, 0.0);
        }
        let at = self.pi.iter().position(|&p| p == best).unwrap_or(0);
        let (i, j) = (at / nz, at % nz);
        let pw = self.pi[((i + nt - 1) % nt) * nz + j];
        let pe = self.pi[((i + 1) % nt) * nz + j];
        let curvature = pw - 2.0 * best + pe;
        let shift = if curvature < 0.0 {
            (0.5 * (pw - pe) / curvature).clamp(-0.5, 0.5)
        } else {
            0.0
        };
        let peak = best - 0.25 * (pw - pe) * shift;
        (
            self.pressure_scale * peak.max(best),
            wrap_angle_rad((i as f64 + shift) * self.dtheta),
        )
    }

    /// The longest circular run of pressurised nodes in the mid-plane: (first, last) column.
    /// A film that is pressurised all round is reported as starting just after its lowest node.
    fn midplane_zone(&self) -> Option<(usize, usize)> {
        let (nt, nz) = (self.grid.n_theta, self.grid.n_z);
        let positive = |i: usize| self.pi[(i % nt) * nz] > 0.0;
        let Some(gap) = (0..nt).find(|&i| !positive(i)) else {
            let lowest = (0..nt)
                .min_by(|&a, &b| self.pi[a * nz].total_cmp(&self.pi[b * nz]))
                .unwrap_or(0);
            return Some(((lowest + 1) % nt, lowest));
        };
        let (mut best, mut run_start, mut len) = (None::<(usize, usize)>, 0, 0);
        for m in 1..=nt {
            let i = gap + m;
            if positive(i) {
                if len == 0 {
                    run_start = i;
                }
                len += 1;
                if best.is_none_or(|(_, l)| len > l) {
                    best = Some((run_start, len));
                }
            } else {
                len = 0;
            }
        }
        best.map(|(s, l)| (s % nt, (s + l - 1) % nt))
    }

    /// ζ1 (rad): where the pressure rises from zero before column `s`, by linear extrapolation
    /// of the first two pressurised nodes (the pressure leaves zero with a finite slope).
    fn zone_start_angle(&self, s: usize) -> f64 {
        let (nt, nz) = (self.grid.n_theta, self.grid.n_z);
        let p0 = self.pi[s * nz];
        let p1 = self.pi[((s + 1) % nt) * nz];
        let back = if p1 > p0 {
            (p0 / (p1 - p0)).min(1.0)
        } else {
            0.5
        };
        wrap_angle_rad((s as f64 - back) * self.dtheta)
    }

    /// ζ2 (rad): where the film ruptures after column `e`. There p = ∂p/∂θ = 0 (seed eq. 6), so
    /// p grows quadratically away from ζ2 and √p is extrapolated linearly to zero.
    fn zone_end_angle(&self, e: usize) -> f64 {
        let (nt, nz) = (self.grid.n_theta, self.grid.n_z);
        let pe = self.pi[e * nz].max(0.0).sqrt();
        let pb = self.pi[((e + nt - 1) % nt) * nz].max(0.0).sqrt();
        let ahead = if pb > pe {
            (pe / (pb - pe)).min(1.0)
        } else {
            0.5
        };
        wrap_angle_rad((e as f64 + ahead) * self.dtheta)
    }

    /// Friction torque on the journal (N·m): Couette shear µωR/h over the full 360° (the
    /// Raimondi–Boyd convention) plus the pressure-flow shear (h/2R) ∂p/∂θ where the film is whole.
    /// A mass-conserving film shears only its streamers in the ruptured zone: there the Couette
    /// shear is weighted by the fluid fraction φ (issue 18; 1 with the Reynolds condition).
    fn friction_torque(&self, speed_rad_s: f64) -> f64 {
        let (nt, nz) = (self.grid.n_theta, self.grid.n_z);
        let r = self.geometry.radius_m();
        let c = self.geometry.radial_clearance_m;
        let mu = self.lubricant.viscosity_pa_s;
        // with the turbulent Couette shear factor (eq. T3; 1 laminar)
        // and the viscosity of each column of a thermal film (µ(ζ)/µ₀, eq. E1)
        let ratio = |i: usize| self.viscosity_ratio.get(i).copied().unwrap_or(1.0);
        let inverse_h: f64 = self
            .h_node
            .iter()
            .enumerate()
            .map(|(i, &h)| ratio(i) * self.factors.couette_shear(h) / h * self.sheared_share(i))
            .sum();
        let couette =
            mu * speed_rad_s * r.powi(3) * self.geometry.length_m / c * inverse_h * self.dtheta;
        // (R/2) ∫∫ h ∂p/∂θ dθ dz over both halves = R² c ps Σ_j w_j Σ_i H_{i+½} (Π_{i+1} − Π_i)
        let mut poiseuille = 0.0;
        for j in 0..nz {
            let mut row = 0.0;
            for i in 0..nt {
                let east = (i + 1) % nt;
                row += self.h_face[i] * (self.pi[east * nz + j] - self.pi[i * nz + j]);
            }
            poiseuille += self.row_width(j) * row;
        }
        couette + r * r * c * self.pressure_scale * poiseuille
    }

    /// The share of column `i` that the journal shears: 1 with the Reynolds condition (the
    /// full-film convention), the width-weighted mean fluid fraction φ of the column for a
    /// mass-conserving film (its streamers, φ < 1 in the ruptured zone).
    fn sheared_share(&self, i: usize) -> f64 {
        if self.cavitation != crate::film::Cavitation::MassConserving {
            return 1.0;
        }
        let nz = self.grid.n_z;
        let (mut sum, mut width) = (0.0, 0.0);
        for j in 0..nz {
            sum += self.row_width(j) * self.phi[i * nz + j];
            width += self.row_width(j);
        }
        sum / width
    }

    /// Flow out of both bearing ends (m³/s): the finite-volume flux through the edge faces.
    fn side_flow(&self) -> f64 {
        let (nt, nz) = (self.grid.n_theta, self.grid.n_z);
        let r = self.geometry.radius_m();
        let c = self.geometry.radial_clearance_m;
        let flux: f64 = (0..nt)
            .map(|i| self.h3_node[i] * self.pi[i * nz + nz - 1])
            .sum();
        flux * self.dtheta * c * r * r / self.dz
    }

    /// Circumferential flow into the pressure zone through the face before column `s` (m³/s):
    /// Couette flow ωR h/2 less the pressure flow, over the whole length.
    fn inflow(&self, s: usize, speed_rad_s: f64) -> f64 {
        let (nt, nz) = (self.grid.n_theta, self.grid.n_z);
        let west = (s + nt - 1) % nt;
        let h = self.h_face[west];
        let r = self.geometry.radius_m();
        let c = self.geometry.radial_clearance_m;
        let mut q = 0.0;
        for j in 0..nz {
            let dpi = self.pi[s * nz + j] - self.pi[west * nz + j];
            // the Couette flow carries the fluid fraction of the upwind node (1 with the
            // Reynolds condition)
            let couette = speed_rad_s * h * self.phi[west * nz + j];
            q += self.row_width(j) * (couette - self.h3_face[west] * dpi / self.dtheta);
        }
        r * r * c * q
    }

    /// The mid-plane pressure zone of the last solve, (first, last) column, as ζ1 and ζ2 report it.
    pub(crate) fn pressure_zone(&self) -> Option<(usize, usize)> {
        self.midplane_zone()
    }

    /// Film thickness at column i's node of the last solve, h/c.
    pub(crate) fn film_thickness(&self, i: usize) -> f64 {
        self.h_node[i]
    }

    /// The heat budget of the last converged solve at `speed_rad_s`, per grid column i (both
    /// halves of the bearing; the thermal film's inputs, `src/film/thermal.rs` eq. E2–E3):
    /// `flow[i]` the circumferential flow through the θ-face after column i (m³/s, the solver's
    /// own flux, as [`Self::inflow`]); `couette_w[i]` the Couette dissipation µω²R²/h of a full
    /// film over the column's cells (W); `pressure_w[i]` the pressure-flow dissipation
    /// h³|∇p|²/(12µ) (W), each face's share split between the cells it joins (an edge face's to
    /// its one cell). With p = 6µ₀(R/c)²Π and G the conductance H³/(µ/µ₀), the latter is
    /// 3µ₀R²G/c·|∇Π|² per unit area.
    pub(crate) fn column_budget(
        &self,
        speed_rad_s: f64,
        flow: &mut [f64],
        couette_w: &mut [f64],
        pressure_w: &mut [f64],
    ) {
        let (nt, nz) = (self.grid.n_theta, self.grid.n_z);
        let r = self.geometry.radius_m();
        let c = self.geometry.radial_clearance_m;
        let mu0 = self.lubricant.viscosity_pa_s;
        let ratio = |i: usize| self.viscosity_ratio.get(i).copied().unwrap_or(1.0);
        // both halves: the cells of a column cover R²Δθ · L/R
        let column_area = r * self.geometry.length_m * self.dtheta;
        let per_gradient = 3.0 * mu0 * r * r / c;
        pressure_w[..nt].fill(0.0);
        for i in 0..nt {
            let h = self.h_node[i];
            couette_w[i] = mu0 * ratio(i) * (speed_rad_s * r).powi(2) / (c * h)
                * self.factors.couette_shear(h)
                * column_area;
            let east = (i + 1) % nt;
            let mut q = 0.0;
            for j in 0..nz {
                let w = self.row_width(j);
                let dpi = (self.pi[east * nz + j] - self.pi[i * nz + j]) / self.dtheta;
                q += w * (speed_rad_s * self.h_face[i] - self.h3_face[i] * dpi);
                let face =
                    per_gradient * self.h3_face[i] * dpi * dpi * 2.0 * r * r * self.dtheta * w;
                pressure_w[i] += 0.5 * face;
                pressure_w[east] += 0.5 * face;
                let above = if j + 1 < nz {
                    self.pi[i * nz + j + 1]
                } else {
                    0.0
                };
                let dz_pi = (above - self.pi[i * nz + j]) / self.dz;
                pressure_w[i] += per_gradient
                    * self.h3_node[i]
                    * dz_pi
                    * dz_pi
                    * 2.0
                    * r
                    * r
                    * self.dtheta
                    * self.dz;
            }
            flow[i] = r * r * c * q;
        }
    }
}
