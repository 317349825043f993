//! Pixel-size metadata: ImageJ ImageDescription, OME-XML and TIFF resolution tags.
//!
//! Priority (see `docs/conventions.md`): OME-XML > ImageJ description + XResolution >
//! ResolutionUnit centimetre/inch > none. OME-TIFF writers often put a meaningless 72 dpi in the
//! resolution tags, so the XML wins; ImageJ writes XResolution as pixels per `unit=` with
//! ResolutionUnit = NONE, so the unit must come from the description.

use crate::units::Dimension;

/// What an ImageJ ImageDescription (`ImageJ=1.x\nimages=…\nunit=…`) says.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ImageJDescription {
    /// Length of one `unit` in metres; `None` when the unit is blank, "pixel" or unknown.
    pub unit_m: Option<f64>,
    /// The unit as written.
    pub unit_text: Option<String>,
    /// `channels=` (hyperstack channels interleaved page by page, channel fastest).
    pub channels: Option<usize>,
    /// `slices=`.
    pub slices: Option<usize>,
    /// `frames=`.
    pub frames: Option<usize>,
    /// `spacing=`: the z step in `unit`s.
    pub spacing: Option<f64>,
    /// `finterval=`: seconds between frames.
    pub finterval: Option<f64>,
    /// `quantity=`: what the values are (contactscope's maps: `height`, `pressure`, `gap`,
    /// `plastic_displacement`, `contact`, `contact_mask`, `intensity`).
    pub quantity: Option<String>,
    /// `vunit=`: the unit of the values (ImageJ's calibration key; contactscope writes `um` and
    /// `MPa`, and no unit for 0/1 maps, masks and micrographs).
    pub value_unit: Option<String>,
}

/// Parse an ImageJ ImageDescription; `None` if the text is not one.
pub fn parse_imagej(description: &str) -> Option<ImageJDescription> {
    if !description.starts_with("ImageJ=") {
        return None;
    }
    let mut meta = ImageJDescription::default();
    for line in description.lines() {
        let Some((key, value)) = line.split_once('=') else {
            continue;
        };
        match key.trim() {
            "unit" => {
                let text = value.trim().to_string();
                meta.unit_m = length_unit_factor(&text);
                meta.unit_text = Some(text);
            }
            "channels" => meta.channels = value.trim().parse().ok(),
            "slices" => meta.slices = value.trim().parse().ok(),
            "frames" => meta.frames = value.trim().parse().ok(),
            "spacing" => meta.spacing = value.trim().parse().ok(),
            "finterval" => meta.finterval = value.trim().parse().ok(),
            "quantity" => meta.quantity = Some(value.trim().to_string()),
            "vunit" => meta.value_unit = Some(value.trim().to_string()),
            _ => {}
        }
    }
    Some(meta)
}

/// Metres per unit for the unit spellings microscope software writes (`micron`, `µm`,
/// `\u00B5m` with a literal backslash, `um`, `nm`, …). `None` for blank, `pixel` or unknown.
pub fn length_unit_factor(unit: &str) -> Option<f64> {
    let normalised = unit
        .trim()
        .replace("\\u00B5", "µ")
        .replace("\\u00b5", "µ")
        .replace("&#181;", "µ")
        .replace("&#xB5;", "µ")
        .replace("&#xb5;", "µ")
        .replace('\u{3bc}', "µ");
    match normalised.as_str() {
        "inch" | "in" => Some(0.0254),
        "Å" | "angstrom" => Some(1e-10),
        u => Dimension::Length.factor(u),
    }
}

/// Physical pixel size (x, y) in metres from OME-XML, if the first `<Pixels>` element gives
/// PhysicalSizeX (PhysicalSizeY defaults to X). Units default to µm, as the OME schema says.
pub fn parse_ome_pixel_size(description: &str) -> Option<(f64, f64)> {
    if !description.contains("<OME") {
        return None;
    }
    let start = description.find("<Pixels ")?;
    let rest = &description[start..];
    let element = &rest[..rest.find('>')?];
    let size = |axis: &str| -> Option<f64> {
        let value: f64 = xml_attribute(element, &format!("PhysicalSize{axis}"))?
            .parse()
            .ok()?;
        let unit = xml_attribute(element, &format!("PhysicalSize{axis}Unit")).unwrap_or("µm");
        let metres = value * length_unit_factor(unit)?;
        (metres.is_finite() && metres > 0.0).then_some(metres)
    };
    let x = size("X")?;
    Some((x, size("Y").unwrap_or(x)))
}

fn xml_attribute<'a>(element: &'a str, name: &str) -> Option<&'a str> {
    let mut search = element;
    loop {
        let at = search.find(name)?;
        let before_ok = search[..at]
            .chars()
            .next_back()
            .is_some_and(char::is_whitespace);
        let after = search[at + name.len()..].trim_start();
        if before_ok {
            if let Some(value) = after.strip_prefix('=') {
                let value = value.trim_start();
                let quote = value.chars().next()?;
                if quote == '"' || quote == '\'' {
                    let value = &value[1..];
                    return Some(&value[..value.find(quote)?]);
                }
            }
        }
        search = &search[at + name.len()..];
    }
}

/// Display resolutions that image writers put in files by default; they say nothing about the
/// specimen and are ignored.
pub fn is_display_dpi(pixels_per_inch: f64) -> bool {
    [72.0, 96.0, 150.0, 300.0, 600.0, 1.0]
        .iter()
        .any(|d| (pixels_per_inch - d).abs() < 1e-9)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn imagej_units_and_channels() {
        let d = "ImageJ=1.53t\nimages=90\nchannels=2\nslices=45\nunit=\\u00B5m\nspacing=0.4\n";
        let m = parse_imagej(d).unwrap();
        assert_eq!(m.channels, Some(2));
        assert_eq!(m.slices, Some(45));
        assert_eq!(m.unit_m, Some(1e-6));
        let m = parse_imagej("ImageJ=1.4\nunit=micron\n").unwrap();
        assert_eq!(m.unit_m, Some(1e-6));
        let m = parse_imagej("ImageJ=1.4\nunit= \n").unwrap();
        assert_eq!(m.unit_m, None);
        assert!(parse_imagej("Created by something").is_none());
    }

    #[test]
    fn ome_pixel_sizes_with_units() {
        let xml = r#"<?xml version="1.0"?><OME><Image><Pixels DimensionOrder="XYZCT" ID="Pixels:0" PhysicalSizeX="0.2" PhysicalSizeXUnit="&#181;m" PhysicalSizeY="0.25" SizeX="10"></Pixels></Image></OME>"#;
        let (x, y) = parse_ome_pixel_size(xml).unwrap();
        assert!((x - 0.2e-6).abs() < 1e-15 && (y - 0.25e-6).abs() < 1e-15);
        let xml = r#"<OME><Pixels PhysicalSizeX="200" PhysicalSizeXUnit="nm"/></OME>"#;
        let (x, y) = parse_ome_pixel_size(xml).unwrap();
        assert!((x - 200e-9).abs() < 1e-18 && (y - x).abs() < 1e-18);
        assert!(parse_ome_pixel_size("<OME><Pixels SizeX=\"3\"/></OME>").is_none());
    }
}
