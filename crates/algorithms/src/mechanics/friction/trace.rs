//! A friction trace in memory: x (displacement, plate angle or time) and friction force per
//! sample, SI units, with the column names its CSV form uses (read by
//! `contactscope_jobs::mechanics_csv::read_trace`).

/// The quantity on a trace's x axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum XAxis {
    /// Sliding (plate) displacement, column `displacement_um`, stored in m.
    Displacement,
    /// Rheometer plate angle, column `angle_rad`, stored in rad.
    Angle,
    /// Time, column `time_s`, stored in s.
    Time,
}

impl XAxis {
    /// All axes in the order a trace's columns are searched.
    pub const ALL: [XAxis; 3] = [XAxis::Displacement, XAxis::Angle, XAxis::Time];

    /// The input column name.
    pub fn column(self) -> &'static str {
        match self {
            XAxis::Displacement => "displacement_um",
            XAxis::Angle => "angle_rad",
            XAxis::Time => "time_s",
        }
    }

    /// The output column of the slip position.
    pub fn slip_column(self) -> &'static str {
        match self {
            XAxis::Displacement => "slip_at_um",
            XAxis::Angle => "slip_at_rad",
            XAxis::Time => "slip_at_s",
        }
    }

    /// SI value of one unit of the column (µm → m).
    pub fn si_per_unit(self) -> f64 {
        match self {
            XAxis::Displacement => 1e-6,
            XAxis::Angle | XAxis::Time => 1.0,
        }
    }

    /// An SI value in the column's unit.
    pub fn to_column_unit(self, si: f64) -> f64 {
        si / self.si_per_unit()
    }
}

/// One friction trace in SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct Trace {
    /// What `x` is.
    pub x_axis: XAxis,
    /// x per sample (m, rad or s), increasing.
    pub x: Vec<f64>,
    /// Friction force per sample, N.
    pub friction_n: Vec<f64>,
    /// Median of the trace's normal-force column, N, if it has one.
    pub normal_force_n: Option<f64>,
}

/// Fewest samples a trace may have: loading, slip and a kinetic level need some of each.
pub const MIN_SAMPLES: usize = 10;
