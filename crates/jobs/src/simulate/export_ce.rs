//! `simulate --export contact-engineering`: the results in the layout of contact.engineering's
//! contact-mechanics download (TopoBank's `contact_mechanics.zip`, written by topobank-contact's
//! `download_contact_mechanics_analyses_as_zip`), so that a lab can put ours beside theirs.
//!
//! `contact_mechanics.zip` (entries stored, not compressed, as contact.engineering's):
//!
//! * `README.txt`: what the files are, in our words.
//! * `<measurement>/plot.csv`: one row per load, in increasing pressure, as pandas writes a
//!   table (an unnamed zero-based index column, then `Normalized pressure p/E*`, `Fractional
//!   contact area A/A0`, `Normalized mean gap u/h_rms`, `converged` (`True`/`False`),
//!   `filename`), numbers as Python prints them (shortest round trip).
//! * `<measurement>/result-step-<N>.nc`: one NetCDF-3 (64-bit offset) file per load, N the
//!   load's index in the order given, with dimensions `x` (first index) and `y` and the
//!   variables `pressure` (in units of E*), `contacting_points` (int8 0/1 with `dtype = "bool"`,
//!   as xarray stores booleans), `gap` and `displacement` (m); the global attributes
//!   `mean_pressure` (E*), `total_contact_area` (fraction), `type` (`periodic` or
//!   `nonperiodic`) and, for the hardness model, `hardness` (E*); and the attributes that
//!   contact.engineering's current code adds: `units` on each variable, `mean_displacement`
//!   (the rigid-body offset d, m), `converged` (0/1), `length_unit` (`m`), `elastic_modulus`
//!   and `elastic_modulus_unit` (E* in Pa).
//! * `<measurement>/info.txt`: `# `-prefixed lines naming the input and its SHA-256, the
//!   parameters, contactscope's version and source revision, and the method's references.
//!
//! The normalisations are contact.engineering's: p/E* = F/(A0·E*) with A0 the map's area
//! nx·ny·Δx·Δy; A/A0 the fraction of pixels with p > 0; the mean gap over every pixel divided by
//! the rms height (about the mean) of the body in contact (sphere included when one is added).
//! In contact.engineering's convention the gap is g = u − h − d ≥ 0 with the displacement u
//! positive into the elastic body; ours is g = s − δ + u with s = max(h) − h, so u is the same
//! field and d = δ − max(h). The mean gap is ours at convergence (the unclipped gap that
//! contact.engineering averages is zero on the contact to the solver's tolerance).

use std::io::Write;
use std::path::{Path, PathBuf};

use contactscope::solver::simulate::Model;
use contactscope_formats::topography::netcdf_write::{
    write_netcdf, NcAttr, NcData, NcFile, NcVariable,
};

use super::{LoadMaps, LoadObserver, ModelChoice, SimulateOutcome, SimulateRequest};
use crate::error::{Error, Result};
use crate::heights::HeightInput;
use crate::staging::Staging;

/// The file name of the export in the output folder.
pub const ZIP_NAME: &str = "contact_mechanics.zip";

/// The NetCDF files as they come, then the archive.
pub struct CeExport {
    dir: tempfile::TempDir,
    rows: Vec<Row>,
    e_star_pa: f64,
    periodic: bool,
    hardness_pa: Option<f64>,
    /// rms height of the body, its area A0 and its highest point, from the first load.
    body: Option<(f64, f64, f64)>,
}

struct Row {
    pressure: f64,
    fraction: f64,
    gap: f64,
    step: usize,
}

impl CeExport {
    /// Ready for `request`'s loads; refused for Greenwood–Tripp (no half-space fields).
    pub fn new(request: &SimulateRequest) -> Result<Self> {
        let hardness_pa = match request.model {
            ModelChoice::GreenwoodTripp => {
                return Err(Error::InvalidArgument(
                    "--export contact-engineering holds half-space results (pressure, gap, \
                     displacement per load); the Greenwood–Tripp model has none"
                        .into(),
                ))
            }
            ModelChoice::HalfSpace(Model::Hardness { hardness_pa, .. }) => Some(hardness_pa),
            ModelChoice::HalfSpace(_) => None,
        };
        Ok(CeExport {
            dir: tempfile::tempdir().map_err(|e| Error::InvalidArgument(e.to_string()))?,
            rows: Vec::new(),
            e_star_pa: request.e_star_pa,
            // As `run` decides: a container's measurement marked periodic is solved periodic.
            periodic: request.periodic || request.heights.stated_periodic()?,
            hardness_pa,
            body: None,
        })
    }

    /// Write load `index`'s NetCDF file.
    pub fn step(&mut self, index: usize, maps: &LoadMaps<'_>) -> Result<()> {
        let LoadMaps::HalfSpace { body, step, .. } = maps else {
            return Ok(());
        };
        let periodic = self.periodic;
        // The body is the same at every load: its rms height, area A0 and top, once.
        let (h_rms, a0, top) = *self.body.get_or_insert_with(|| {
            let top = body
                .heights
                .iter()
                .copied()
                .fold(f64::NEG_INFINITY, f64::max);
            (body.rms_height(), body.area_m2(), top)
        });
        let (ny, nx) = body.heights.dim();
        let s = &step.solution;
        // (x, y) with x the slow index: the transpose of our rows = y.
        let xy = |v: &[f64], f: &dyn Fn(f64) -> f64| -> Vec<f64> {
            (0..nx)
                .flat_map(|j| (0..ny).map(move |i| (i, j)))
                .map(|(i, j)| f(v[i * nx + j]))
                .collect()
        };
        let e = self.e_star_pa;
        let pressure = xy(&s.pressure, &|p| p / e);
        let contact: Vec<i8> = xy(&s.pressure, &|p| f64::from(u8::from(p > 0.0)))
            .into_iter()
            .map(|c| c as i8)
            .collect();
        let gap = xy(&s.gap, &|g| g);
        let displacement = xy(&s.displacement, &|u| u);
        let mean_pressure = step.force_n / (a0 * e);
        let mean_gap = s.gap.iter().sum::<f64>() / s.gap.len() as f64;
        let field = |name: &str, data: Vec<f64>, unit: &str| {
            // (xarray adds `_FillValue = NaN` to float variables; every value here is defined,
            // and the netcdf3 crate cannot define a NaN attribute, so none is written.)
            NcVariable::new(name, &["x", "y"], NcData::F64(data))
                .attr("units", NcAttr::Text(unit.into()))
        };
        let mut attrs = vec![
            (
                "mean_pressure".to_string(),
                NcAttr::F64(vec![mean_pressure]),
            ),
            (
                "mean_displacement".into(),
                NcAttr::F64(vec![s.approach - top]),
            ),
            (
                "total_contact_area".into(),
                NcAttr::F64(vec![step.contact_fraction]),
            ),
            ("converged".into(), NcAttr::I32(vec![1])),
            ("length_unit".into(), NcAttr::Text("m".into())),
            ("elastic_modulus".into(), NcAttr::F64(vec![e])),
            ("elastic_modulus_unit".into(), NcAttr::Text("Pa".into())),
            (
                "type".into(),
                NcAttr::Text(if periodic { "periodic" } else { "nonperiodic" }.into()),
            ),
        ];
        if let Some(h) = self.hardness_pa {
            attrs.push(("hardness".into(), NcAttr::F64(vec![h / e])));
        }
        let file = NcFile {
            dims: vec![("x".into(), nx), ("y".into(), ny)],
            attrs,
            vars: vec![
                field("pressure", pressure, "E*"),
                NcVariable::new("contacting_points", &["x", "y"], NcData::I8(contact))
                    .attr("dtype", NcAttr::Text("bool".into()))
                    .attr("units", NcAttr::Text("1".into())),
                field("gap", gap, "m"),
                field("displacement", displacement, "m"),
            ],
        };
        write_netcdf(&self.dir.path().join(step_file(index)), &file)?;
        self.rows.push(Row {
            pressure: mean_pressure,
            fraction: step.contact_fraction,
            gap: mean_gap / h_rms,
            step: index,
        });
        Ok(())
    }

    /// `plot.csv`: the rows in increasing pressure, as pandas' `to_csv` writes them.
    fn plot_csv(&self) -> String {
        let mut order: Vec<&Row> = self.rows.iter().collect();
        order.sort_by(|a, b| a.pressure.total_cmp(&b.pressure));
        let mut out = String::from(
            ",Normalized pressure p/E*,Fractional contact area A/A0,Normalized mean gap \
             u/h_rms,converged,filename\n",
        );
        for (k, r) in order.iter().enumerate() {
            out.push_str(&format!(
                "{k},{},{},{},True,{}\n",
                python_float(r.pressure),
                python_float(r.fraction),
                python_float(r.gap),
                step_file(r.step)
            ));
        }
        out
    }

    /// Stage `contact_mechanics.zip` (module docs) in `staging`.
    pub fn finish(
        self,
        staging: &Staging,
        request: &SimulateRequest,
        outcome: &SimulateOutcome,
    ) -> Result<()> {
        staging.write_with(ZIP_NAME, |file| self.write_zip(file, request, outcome))?;
        Ok(())
    }

    /// Write the archive to `path` (atomically; Python's `simulate(..., contact_engineering=)`).
    pub fn finish_to(
        self,
        path: &Path,
        request: &SimulateRequest,
        outcome: &SimulateOutcome,
    ) -> Result<()> {
        let inputs: Vec<PathBuf> = match &request.heights {
            HeightInput::File(s) => vec![s.path.clone()],
            HeightInput::Memory { .. } => Vec::new(),
        };
        crate::staging::write_atomic_with(path, &inputs, |file| {
            self.write_zip(file, request, outcome)
        })
    }

    fn write_zip(
        &self,
        file: &mut std::fs::File,
        request: &SimulateRequest,
        outcome: &SimulateOutcome,
    ) -> Result<()> {
        let name = measurement_name(&request.heights);
        let info = info_txt(request, outcome, &name)?;
        let plot = self.plot_csv();
        let mut steps: Vec<usize> = self.rows.iter().map(|r| r.step).collect();
        steps.sort_unstable();
        let fail = |e: String| Error::InvalidArgument(format!("{ZIP_NAME}: {e}"));
        let mut zip = zip::ZipWriter::new(file);
        let stored = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Stored)
            .large_file(true);
        let mut put = |entry: String, bytes: &mut dyn std::io::Read| -> Result<()> {
            zip.start_file(entry, stored)
                .map_err(|e| fail(e.to_string()))?;
            std::io::copy(bytes, &mut zip).map_err(|e| fail(e.to_string()))?;
            Ok(())
        };
        put("README.txt".into(), &mut README.as_bytes())?;
        put(format!("{name}/plot.csv"), &mut plot.as_bytes())?;
        for s in &steps {
            let path = self.dir.path().join(step_file(*s));
            let mut f = std::fs::File::open(&path).map_err(|e| Error::io(&path, e))?;
            put(format!("{name}/{}", step_file(*s)), &mut f)?;
        }
        put(format!("{name}/info.txt"), &mut info.as_bytes())?;
        zip.finish()
            .map_err(|e| fail(e.to_string()))?
            .flush()
            .map_err(|e| fail(e.to_string()))
    }
}

/// An observer that hands every load to the export, then to `inner` (Python's `simulate`,
/// which keeps the maps it is asked for).
pub struct Exporting<'a> {
    /// The caller's observer.
    pub inner: &'a mut dyn LoadObserver,
    /// The export.
    pub export: &'a mut CeExport,
}

impl LoadObserver for Exporting<'_> {
    fn load(&mut self, index: usize, total: usize, maps: LoadMaps<'_>) -> Result<()> {
        self.export.step(index, &maps)?;
        self.inner.load(index, total, maps)
    }
}

/// `simulate --export surface-container`: after every load, the body's surface with the
/// plastic displacement taken off (`load_NNN deformed`, heights in m as the body's, sphere
/// included when one was added) and the plastic displacement itself (`load_NNN plastic`, m), as
/// topographies of one surface `deformed` in a contact.engineering surface container
/// (`deformed_surfaces.zip`), readable by SurfaceTopography. Only for the plastic models (the
/// elastic model leaves no permanent deformation).
pub struct DeformedExport {
    builder: contactscope_formats::topography::container_write::ContainerBuilder,
    periodic: bool,
}

/// The file name of the deformed surfaces' container in the output folder.
pub const DEFORMED_NAME: &str = "deformed_surfaces.zip";

impl DeformedExport {
    /// Ready for `request`'s loads; refused for the elastic and Greenwood–Tripp models.
    pub fn new(request: &SimulateRequest) -> Result<Self> {
        if !matches!(
            request.model,
            ModelChoice::HalfSpace(Model::Hardness { .. } | Model::Hardening { .. })
        ) {
            return Err(Error::InvalidArgument(format!(
                "--export surface-container writes the plastically deformed surfaces; the {} \
                 model leaves none (use --model hardness or hardening)",
                request.model.name()
            )));
        }
        let mut builder =
            contactscope_formats::topography::container_write::ContainerBuilder::new()?;
        builder.surface(
            "deformed",
            "contactscope simulate: the surface after each load's plastic flow, and the \
             plastic displacement",
        );
        Ok(DeformedExport {
            builder,
            periodic: request.periodic || request.heights.stated_periodic()?,
        })
    }

    /// Add load `index`'s deformed surface and plastic displacement.
    pub fn step(&mut self, index: usize, maps: &LoadMaps<'_>) -> Result<()> {
        use contactscope_formats::topography::container_write::OutTopography;
        let LoadMaps::HalfSpace { body, step, .. } = maps else {
            return Ok(());
        };
        let plastic = ndarray::Array2::from_shape_vec(body.heights.dim(), step.plastic_m.clone())
            .map_err(|e| Error::InvalidArgument(e.to_string()))?;
        let deformed = &body.heights - &plastic;
        let n = index + 1;
        for (what, heights) in [("deformed", &deformed), ("plastic", &plastic)] {
            self.builder.add(&OutTopography {
                name: format!("load_{n:03} {what}"),
                heights,
                pixel_size_m: (body.dx_m, body.dy_m),
                periodic: self.periodic,
                info: serde_json::json!({
                    "load": n,
                    "force_N": step.force_n,
                    "map": what,
                    "unit": "m",
                }),
            })?;
        }
        Ok(())
    }

    /// Stage `deformed_surfaces.zip`.
    pub fn finish(self, staging: &Staging) -> Result<()> {
        crate::container_out::stage_container(
            staging,
            DEFORMED_NAME,
            self.builder,
            "It holds the surface `deformed`: for every load of a `contactscope simulate` run, \
             the body's surface after the load's plastic flow (`load_NNN deformed`) and the \
             plastic displacement (`load_NNN plastic`).",
        )
    }
}

fn step_file(index: usize) -> String {
    format!("result-step-{index}.nc")
}

/// The folder name inside the archive: the container measurement's name, else the file's
/// stem, else `heights`; characters that cannot be in a path become `_`.
fn measurement_name(input: &HeightInput) -> String {
    let raw = match input {
        HeightInput::File(s) => match (&s.measurement, s.is_container()) {
            (m, true) => contactscope_formats::topography::container::Container::open(&s.path)
                .ok()
                .and_then(|c| c.find(m.as_deref()).ok().map(|m| m.name.clone())),
            _ => None,
        }
        .or_else(|| s.path.file_stem().map(|n| n.to_string_lossy().into_owned())),
        HeightInput::Memory { .. } => None,
    }
    .unwrap_or_else(|| "heights".into());
    let clean: String = raw
        .chars()
        .map(|c| {
            if c == '/' || c == '\\' || c.is_control() {
                '_'
            } else {
                c
            }
        })
        .collect();
    match clean.trim() {
        "" | "." | ".." => "heights".into(),
        t => t.to_string(),
    }
}

/// A float as Python's `repr` writes it: the shortest round-trip digits, in exponent form
/// (`1.5e-07`) below 1e-4 or from 1e16 on, with at least one decimal otherwise.
pub fn python_float(v: f64) -> String {
    if v.is_nan() {
        return String::new();
    }
    if v.is_infinite() {
        return if v > 0.0 { "inf" } else { "-inf" }.into();
    }
    let a = v.abs();
    if a != 0.0 && !(1e-4..1e16).contains(&a) {
        let s = format!("{v:e}");
        let (mantissa, exponent) = s.split_once('e').unwrap_or((&s, "0"));
        let e: i32 = exponent.parse().unwrap_or(0);
        let sign = if e < 0 { '-' } else { '+' };
        format!("{mantissa}e{sign}{:02}", e.abs())
    } else {
        let s = format!("{v}");
        if s.contains('.') {
            s
        } else {
            format!("{s}.0")
        }
    }
}

fn info_txt(request: &SimulateRequest, outcome: &SimulateOutcome, name: &str) -> Result<String> {
    let mut lines = Vec::new();
    let headline = format!("topography: {name}");
    lines.push(headline.clone());
    lines.push("=".repeat(headline.chars().count()));
    match &request.heights {
        HeightInput::File(s) => {
            let (hash, bytes) = crate::provenance::sha256_file(&s.path)?;
            lines.push(format!("Input: {} ({bytes} bytes)", s.path.display()));
            lines.push(format!("Input SHA-256: {hash}"));
            if let Some(m) = &s.measurement {
                lines.push(format!("Measurement: {m}"));
            }
        }
        HeightInput::Memory { label, .. } => lines.push(format!("Input: {label} (in memory)")),
    }
    let t = &outcome.topography;
    lines.push(format!(
        "Grid: {} x {} points, pixel size {:e} x {:e} m, detrend {}{}",
        t.nx,
        t.ny,
        t.pixel_size_x_m,
        t.pixel_size_y_m,
        t.detrend,
        t.sphere_radius_m
            .map(|r| format!(", sphere radius {r:e} m added"))
            .unwrap_or_default()
    ));
    lines.push(format!(
        "Further arguments of analysis function: {{'substrate': '{}', 'hardness': {}, \
         'forces_N': [{}], 'contact_modulus_Pa': {}, 'tolerance': {}, 'maxiter': {}, 'model': \
         '{}'}}",
        if outcome.boundary.starts_with("periodic") {
            "periodic"
        } else {
            "nonperiodic"
        },
        match request.model {
            ModelChoice::HalfSpace(Model::Hardness { hardness_pa, .. }) =>
                python_float(hardness_pa / request.e_star_pa),
            _ => "None".into(),
        },
        request
            .loads_n
            .iter()
            .map(|f| python_float(*f))
            .collect::<Vec<_>>()
            .join(", "),
        python_float(request.e_star_pa),
        python_float(request.tolerance),
        request.max_iterations,
        request.model.name()
    ));
    lines.push(format!(
        "Solver: {}, {}",
        outcome.solver.method, outcome.boundary
    ));
    lines.push(format!(
        "Version of 'contactscope': {}",
        crate::provenance::version()
    ));
    lines.push(format!(
        "Source revision of 'contactscope': {}",
        crate::provenance::source_revision().unwrap_or("unknown")
    ));
    lines.push(String::new());
    lines.push("IF YOU USE THIS DATA IN A PUBLICATION, PLEASE CITE THE FOLLOWING PAPERS:".into());
    let mut references = vec![
        "10.1016/S0043-1648(99)00113-1 (Polonsky & Keer 1999, constrained conjugate gradients)",
    ];
    if outcome.boundary.starts_with("periodic") {
        references.push("10.1115/1.2833523 (Stanley & Kato 1997, FFT half-space)");
    } else {
        references.push("Hockney, Methods Comput. Phys. 9, 135 (1970) (free boundaries)");
        references.push("10.1016/S0043-1648(00)00427-0 (Liu, Wang & Liu 2000, DC-FFT)");
    }
    if matches!(request.model, ModelChoice::HalfSpace(Model::Elastic)) {
        references.push("10.1038/s41467-018-02981-y (Weber et al. 2018, the contact data)");
    } else {
        references.push(
            "10.1038/s41467-018-02981-y (Weber et al. 2018, the hardness and hardening models)",
        );
    }
    lines.extend(references.into_iter().map(|r| format!("- {r}")));
    lines.push(String::new());
    Ok(lines.iter().map(|l| format!("# {l}\n")).collect::<String>())
}

const README: &str = "Contents of this ZIP archive
============================
Contact mechanics results written by contactscope in the layout of contact.engineering's
contact-mechanics download, so that they can be read with the same scripts.

The folder is named after the measurement. It holds

- plot.csv: one row per load, sorted by increasing pressure, with the columns
  (unnamed) zero-based row index,
  Normalized pressure p/E*: the normal force divided by the map's nominal area A0 and by
    the contact modulus E*,
  Fractional contact area A/A0: the fraction of points with a positive pressure,
  Normalized mean gap u/h_rms: the mean gap between the surfaces over the whole map,
    divided by the rms height of the body in contact,
  converged: True when the solver reached its tolerance,
  filename: the NetCDF file of that load (the files are numbered in the order the loads
    were given, so the order may differ from the rows').
- result-step-N.nc: one NetCDF-3 file per load, with the dimensions x and y (x first) and
  the variables
    pressure: the local pressure in units of E*,
    contacting_points: 1 where the point is in contact (stored as bytes, dtype = \"bool\"),
    gap: the local gap, m,
    displacement: the elastic displacement of the surface, m,
  and the attributes mean_pressure (E*), total_contact_area (fraction), type (periodic or
  nonperiodic boundaries), mean_displacement (the rigid-body offset, m), converged,
  length_unit, elastic_modulus (E*, in elastic_modulus_unit), and hardness (E*) for the
  hardness model.
- info.txt: the input (with its SHA-256), the parameters, the software version and the
  references to cite.

Reading the files
=================
Python: pandas.read_csv(\"plot.csv\", index_col=0); xarray.open_dataset(\"result-step-0.nc\")
or scipy.io.netcdf_file(\"result-step-0.nc\"). Matlab: ncread(\"result-step-0.nc\", \"pressure\").
The arrays are (x, y): transpose them to get rows along y.
";

#[cfg(test)]
mod tests {
    use super::python_float;

    #[test]
    fn floats_as_python_writes_them() {
        assert_eq!(
            python_float(1.6537790630515102e-07),
            "1.6537790630515102e-07"
        );
        assert_eq!(python_float(0.000244140625), "0.000244140625");
        assert_eq!(python_float(2.1084156348698175), "2.1084156348698175");
        assert_eq!(python_float(1.0), "1.0");
        assert_eq!(python_float(0.0), "0.0");
        assert_eq!(python_float(1e20), "1e+20");
        assert_eq!(python_float(-3.5e-5), "-3.5e-05");
    }
}
