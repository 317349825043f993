//! What an area–load fit rests on: which loads it leaves out and why, and what it cannot say
//! (`docs/outputs.md`, "What a fit rests on"). Shared by `analyze` (micrographs) and `simulate`
//! (computed maps), so that both leave out the same kinds of load and say so in the same words.

use contactscope::analysis::fit::PowerLawFit;

use contactscope_formats::ranges::short;

/// Mean pressures above this (Pa) are beyond any solid contact (the hardest solids yield below
/// it): the forces are almost surely in another unit than assumed, or the areas too small.
pub const IMPLAUSIBLE_PRESSURE_PA: f64 = 20e9;

/// Mean pressures below this (Pa) are below any contact a force gauge in mN resolves on a
/// coverslip (soft elastomers and gels press at kPa to MPa): the pixel size is almost surely too
/// large, or the forces too small.
pub const LOWEST_PLAUSIBLE_PRESSURE_PA: f64 = 1e3;

/// Why a mean pressure (Pa) is implausible, or `None` when it is within
/// [`LOWEST_PLAUSIBLE_PRESSURE_PA`] … [`IMPLAUSIBLE_PRESSURE_PA`].
pub fn implausible_pressure(p_pa: f64) -> Option<&'static str> {
    if !p_pa.is_finite() || p_pa <= 0.0 {
        None
    } else if p_pa > IMPLAUSIBLE_PRESSURE_PA {
        Some("beyond any solid contact (above 20 GPa)")
    } else if p_pa < LOWEST_PLAUSIBLE_PRESSURE_PA {
        Some("below any contact that bears a load (under 1 kPa)")
    } else {
        None
    }
}

/// Why a load is left out of the area–load fits (it stays in the table and on the plot, marked).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Exclusion {
    /// No contact pixel: the area is 0, which a power law cannot take.
    NoContact,
    /// The contact reaches the border of the image or map: its area is cut off (a micrograph)
    /// or the free-boundary solution is not valid (a simulation).
    EdgeContact,
}

/// Where the loads come from, for the words of the warnings.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Source {
    /// Thresholded micrographs.
    Micrographs,
    /// A contact simulation on a height map.
    Simulation,
}

impl Exclusion {
    fn reason(self, source: Source) -> &'static str {
        match (self, source) {
            (Exclusion::NoContact, Source::Micrographs) => "no contact pixel at the threshold",
            (Exclusion::NoContact, Source::Simulation) => {
                "no pixel in contact (the contact is smaller than a pixel)"
            }
            (Exclusion::EdgeContact, Source::Micrographs) => {
                "the contact touches the image border, so its area is cut off"
            }
            (Exclusion::EdgeContact, Source::Simulation) => {
                "the contact reaches the border of the map, where the free-boundary result is \
                 not valid; use a larger map or smaller loads"
            }
        }
    }

    /// The short name the plots' legends use.
    pub fn legend(self) -> &'static str {
        match self {
            Exclusion::NoContact => "no contact",
            Exclusion::EdgeContact => "edge contact",
        }
    }
}

/// One load of a series: its force (mN), its area (any unit), a label for messages and whether
/// it is left out of the fits.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadPoint {
    /// Normal force, mN.
    pub force_mn: f64,
    /// Contact area.
    pub area: f64,
    /// Left out of the fits, and why.
    pub excluded: Option<Exclusion>,
}

impl LoadPoint {
    /// A load with a positive force: a point of the log–log fits unless it is excluded.
    fn loaded(&self) -> bool {
        self.force_mn.is_finite() && self.force_mn > 0.0
    }

    /// Whether the point enters the fits.
    pub fn in_fit(&self) -> bool {
        self.loaded() && self.excluded.is_none() && self.area.is_finite() && self.area > 0.0
    }
}

/// The forces (mN) and areas of the points the fits use.
pub fn fit_points(points: &[LoadPoint]) -> (Vec<f64>, Vec<f64>) {
    points
        .iter()
        .filter(|p| p.in_fit())
        .map(|p| (p.force_mn, p.area))
        .unzip()
}

/// Whether there are loads and none of them can enter a fit: the run's numbers rest on nothing
/// (the command line exits with its own status, `docs/errors.md`).
pub fn nothing_valid(points: &[LoadPoint]) -> bool {
    points.iter().any(LoadPoint::loaded) && !points.iter().any(LoadPoint::in_fit)
}

/// One warning per kind of exclusion, naming the loads (by force) it leaves out.
pub fn exclusion_warnings(points: &[LoadPoint], source: Source) -> Vec<String> {
    let mut out = Vec::new();
    for kind in [Exclusion::EdgeContact, Exclusion::NoContact] {
        let forces: Vec<String> = points
            .iter()
            .filter(|p| p.loaded() && p.excluded == Some(kind))
            .map(|p| format!("{} mN", short(p.force_mn)))
            .collect();
        if forces.is_empty() {
            continue;
        }
        let loaded = points.iter().filter(|p| p.loaded()).count();
        out.push(format!(
            "{} of {loaded} loads left out of the area–load fits and marked on the plot, {}: {}",
            forces.len(),
            forces.join(", "),
            kind.reason(source)
        ));
    }
    out
}

/// What a power-law fit cannot say: too few points or distinct forces, areas that do not change,
/// or no fit at all although there are loads.
pub fn power_law_warnings(fit: Option<&PowerLawFit>, points: &[LoadPoint]) -> Vec<String> {
    let usable = points.iter().filter(|p| p.in_fit()).count();
    let Some(fit) = fit else {
        return if points.iter().any(LoadPoint::loaded) {
            vec![format!(
                "no power-law fit: it needs loads of two different forces with contact ({usable} \
                 of {} loads usable)",
                points.iter().filter(|p| p.loaded()).count()
            )]
        } else {
            Vec::new()
        };
    };
    let mut out = Vec::new();
    // Physics check (`crate::physics`): β < 0, significant when 2 standard errors below 0.
    let significant = fit
        .exponent_se
        .is_some_and(|se| fit.exponent + 2.0 * se < 0.0);
    out.extend(crate::physics::falling_area(fit.exponent, significant));
    if fit.distinct_forces < 3 {
        out.push(format!(
            "the power law rests on {} point(s) at {} distinct force(s): a line through two \
             force levels cannot test the law, so it has no R²{}",
            fit.points,
            fit.distinct_forces,
            if fit.exponent_se.is_none() {
                ", and β has no standard error"
            } else {
                ""
            }
        ));
    }
    let first = points.iter().find(|p| p.in_fit()).map(|p| p.area);
    if fit.points > 1
        && points
            .iter()
            .filter(|p| p.in_fit())
            .all(|p| Some(p.area) == first)
    {
        out.push(format!(
            "every load gives the same area ({}): β = 0 says nothing about the contact; is the \
             same image given for every load?",
            short(first.unwrap_or(f64::NAN))
        ));
    }
    out
}

/// The points of an area–load plot: those of the fits (filled, labelled `label`) and, for each
/// kind of exclusion with points that log axes can show, those left out (open, with a cross).
#[cfg(feature = "plots")]
pub fn point_sets(points: &[LoadPoint], label: &str) -> Vec<crate::plot::PointSet> {
    use crate::plot::PointSet;
    let mut sets = vec![PointSet {
        label: label.to_string(),
        xy: points
            .iter()
            .filter(|p| p.in_fit())
            .map(|p| (p.force_mn, p.area))
            .collect(),
        hollow: false,
    }];
    for kind in [Exclusion::EdgeContact, Exclusion::NoContact] {
        let xy: Vec<(f64, f64)> = points
            .iter()
            .filter(|p| p.loaded() && p.excluded == Some(kind) && p.area > 0.0)
            .map(|p| (p.force_mn, p.area))
            .collect();
        if !xy.is_empty() {
            sets.push(PointSet {
                label: format!("left out of the fits: {}", kind.legend()),
                xy,
                hollow: true,
            });
        }
    }
    sets
}

#[cfg(test)]
mod tests {
    use super::*;
    use contactscope::analysis::fit::fit_power_law;

    #[test]
    fn pressures_outside_solids_are_implausible() {
        assert!(implausible_pressure(1.111e12).unwrap().contains("20 GPa"));
        assert!(implausible_pressure(14.0).unwrap().contains("1 kPa"));
        for fine in [2e3, 2e6, 5e9, f64::NAN, 0.0] {
            assert_eq!(implausible_pressure(fine), None, "{fine}");
        }
    }

    fn point(force_mn: f64, area: f64, excluded: Option<Exclusion>) -> LoadPoint {
        LoadPoint {
            force_mn,
            area,
            excluded,
        }
    }

    #[test]
    fn excluded_loads_leave_the_fit_and_are_named() {
        let points = [
            point(0.0, 5.0, None),
            point(1.0, 0.0, Some(Exclusion::NoContact)),
            point(2.0, 10.0, None),
            point(4.0, 16.0, None),
            point(8.0, 25.0, None),
            point(16.0, 99.0, Some(Exclusion::EdgeContact)),
        ];
        let (f, a) = fit_points(&points);
        assert_eq!(f, [2.0, 4.0, 8.0]);
        assert_eq!(a, [10.0, 16.0, 25.0]);
        let w = exclusion_warnings(&points, Source::Simulation);
        assert_eq!(w.len(), 2, "{w:?}");
        assert!(
            w[0].starts_with("1 of 5 loads") && w[0].contains("plot, 16 mN: "),
            "{}",
            w[0]
        );
        assert!(w[1].contains("plot, 1 mN: no pixel in contact"), "{}", w[1]);
        assert!(!nothing_valid(&points));
        let fit = fit_power_law(&f, &a);
        assert!(power_law_warnings(fit.as_ref(), &points).is_empty());
    }

    #[test]
    fn all_loads_invalid_is_nothing_valid() {
        let edge = Some(Exclusion::EdgeContact);
        let points = [point(1.0, 4.0, edge), point(2.0, 6.0, edge)];
        assert!(nothing_valid(&points));
        let (f, a) = fit_points(&points);
        assert!(fit_power_law(&f, &a).is_none());
        let w = power_law_warnings(None, &points);
        assert!(w[0].contains("0 of 2 loads usable"), "{w:?}");
        // Without forces there is nothing to be valid.
        assert!(!nothing_valid(&[point(0.0, 3.0, None)]));
        assert!(power_law_warnings(None, &[point(0.0, 3.0, None)]).is_empty());
    }

    #[test]
    fn two_forces_and_constant_areas_are_said() {
        let two = [point(1.0, 2.0, None), point(2.0, 3.0, None)];
        let (f, a) = fit_points(&two);
        let w = power_law_warnings(fit_power_law(&f, &a).as_ref(), &two);
        assert!(w[0].contains("2 point(s) at 2 distinct force(s)"), "{w:?}");
        assert!(w[0].contains("no standard error"), "{w:?}");
        // Replicates at two forces: a standard error, still no R².
        let replicates = [
            point(1.0, 2.0, None),
            point(1.0, 2.2, None),
            point(2.0, 3.0, None),
        ];
        let (f, a) = fit_points(&replicates);
        let fit = fit_power_law(&f, &a).unwrap();
        assert!(fit.exponent_se.is_some() && fit.r_squared.is_none());
        let w = power_law_warnings(Some(&fit), &replicates);
        assert!(w[0].contains("3 point(s) at 2 distinct force(s)"), "{w:?}");
        assert!(!w[0].contains("standard error"), "{w:?}");
        let same = [
            point(1.0, 7.0, None),
            point(2.0, 7.0, None),
            point(4.0, 7.0, None),
        ];
        let (f, a) = fit_points(&same);
        let w = power_law_warnings(fit_power_law(&f, &a).as_ref(), &same);
        assert_eq!(w.len(), 1, "{w:?}");
        assert!(w[0].contains("every load gives the same area (7)"), "{w:?}");
    }
}
