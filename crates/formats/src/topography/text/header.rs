//! What a text height map says about itself before its numbers: Gwyddion's ASCII export header
//! (`# Channel: …`, `# Width: 12.34 µm`, `# Height: 5678.9 nm`, `# Value units: m`, in any
//! language Gwyddion writes) and the `key=value` header of other exporters (`h=650 w=650`,
//! `pixel size=3.69862e-007 m`, `data unit=rad`, `height conversion factor (-> m)=6.3e-008`).

use crate::topography::vendor::length_factor;

/// The calibration a text file states; every field is `None` where it says nothing.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct Stated {
    /// Channel name.
    pub channel: Option<String>,
    /// Width and height of the whole map (x, y), m (Gwyddion).
    pub size_m: Option<(f64, f64)>,
    /// Pixel size (square), m (`pixel size=`).
    pub pixel_m: Option<f64>,
    /// Metres per stored value.
    pub unit_m: Option<f64>,
    /// The unit as written, for messages.
    pub unit_text: Option<String>,
    /// Rows and columns the header promises (`h=`, `w=`).
    pub shape: (Option<usize>, Option<usize>),
}

impl Stated {
    /// Whether the header says anything at all (then the numbers are a matrix, never x y z).
    pub fn any(&self) -> bool {
        *self != Stated::default()
    }
}

/// Words Gwyddion's translations use for the four header lines (lower case).
const CHANNEL: &[&str] = &["channel", "kanal", "canal", "canale", "kanál", "kanał"];
const WIDTH: &[&str] = &[
    "width",
    "breite",
    "largeur",
    "anchura",
    "ancho",
    "larghezza",
    "x-length",
];
const HEIGHT: &[&str] = &["height", "höhe", "hauteur", "altura", "altezza", "y-length"];
const VALUE_UNITS: &[&str] = &["value units", "einheit der werte", "unités des valeurs"];

/// A `# key: value` comment line → (key, value).
fn comment_entry(line: &str) -> Option<(String, String)> {
    let body = line.trim().strip_prefix('#')?.trim();
    let (key, value) = body.split_once(':')?;
    Some((key.trim().to_lowercase(), value.trim().to_string()))
}

/// `12.34 µm` → metres.
fn length(text: &str) -> Option<f64> {
    let (value, unit) = text.trim().split_once(char::is_whitespace)?;
    let v: f64 = value.trim().parse().ok()?;
    let f = length_factor(unit.trim())?;
    (v.is_finite() && v > 0.0).then_some(v * f)
}

/// Read the comment lines of a Gwyddion ASCII export. The keys are matched by name in the
/// languages above; a block of exactly four entries whose second and third are lengths is read
/// by position (Gwyddion always writes channel, width, height, value units in that order), so
/// that a language not listed reads too. Returns an error message for a header that states
/// something unreadable (a width that is not a length, a value unit that is not one).
pub(crate) fn gwyddion(comments: &[&str], stated: &mut Stated) -> Result<(), String> {
    let entries: Vec<(String, String)> = comments.iter().filter_map(|l| comment_entry(l)).collect();
    let find = |words: &[&str]| {
        entries
            .iter()
            .find(|(k, _)| words.contains(&k.as_str()))
            .map(|(_, v)| v.clone())
    };
    let by_position =
        entries.len() == 4 && length(&entries[1].1).is_some() && length(&entries[2].1).is_some();
    let pick = |words: &[&str], position: usize| {
        find(words).or_else(|| by_position.then(|| entries[position].1.clone()))
    };
    if let Some(name) = pick(CHANNEL, 0) {
        stated.channel = Some(name);
    }
    match (pick(WIDTH, 1), pick(HEIGHT, 2)) {
        (None, None) => {}
        (Some(w), Some(h)) => {
            let (x, y) = (length(&w), length(&h));
            match (x, y) {
                (Some(x), Some(y)) => stated.size_m = Some((x, y)),
                _ => return Err(format!("header size '{w}' × '{h}' is not two lengths")),
            }
        }
        (Some(_), None) | (None, Some(_)) => {
            return Err("header gives the width or the height of the map, not both".into())
        }
    }
    if let Some(unit) = pick(VALUE_UNITS, 3) {
        stated.unit_m = Some(
            length_factor(&unit)
                .ok_or_else(|| format!("values in '{unit}', not heights (not a length unit)"))?,
        );
        stated.unit_text = Some(unit);
    }
    Ok(())
}

/// Whether a line is a `key=value` header line (`h=650 w=650`, `pixel size=… m`).
pub(crate) fn is_key_value(line: &str) -> bool {
    let t = line.trim();
    t.contains('=') && t.chars().next().is_some_and(|c| c.is_alphabetic())
}

/// Read one `key=value` header line (several pairs may share a line when the keys are single
/// words: `h=650 w=650`).
pub(crate) fn key_value(line: &str, stated: &mut Stated) -> Result<(), String> {
    let t = line.trim();
    let pairs: Vec<(String, String)> = if t.matches('=').count() > 1 {
        t.split_whitespace()
            .filter_map(|p| p.split_once('='))
            .map(|(k, v)| (k.trim().to_lowercase(), v.trim().to_string()))
            .collect()
    } else {
        t.split_once('=')
            .map(|(k, v)| vec![(k.trim().to_lowercase(), v.trim().to_string())])
            .unwrap_or_default()
    };
    for (key, value) in pairs {
        let count = || {
            value
                .parse::<usize>()
                .ok()
                .filter(|&n| n > 0)
                .ok_or_else(|| format!("'{key}={value}' is not a positive count"))
        };
        match key.as_str() {
            "h" => stated.shape.0 = Some(count()?),
            "w" => stated.shape.1 = Some(count()?),
            "pixel size" => {
                stated.pixel_m = Some(
                    length(&value)
                        .ok_or_else(|| format!("pixel size '{value}' is not a length"))?,
                )
            }
            "data unit" => {
                // A length is the heights' unit; another unit (rad) needs the conversion below.
                if stated.unit_m.is_none() {
                    if let Some(f) = length_factor(&value) {
                        stated.unit_m = Some(f);
                    }
                }
                stated.unit_text.get_or_insert(value);
            }
            k if k.starts_with("height conversion factor") => {
                let target = k
                    .split_once("->")
                    .map(|(_, u)| u.trim().trim_end_matches(')').trim().to_string())
                    .unwrap_or_else(|| "m".into());
                let factor: f64 = value
                    .parse()
                    .ok()
                    .filter(|f: &f64| f.is_finite() && *f != 0.0)
                    .ok_or_else(|| format!("height conversion factor '{value}' is not a number"))?;
                let per = length_factor(&target)
                    .ok_or_else(|| format!("height conversion to '{target}', not a length"))?;
                stated.unit_m = Some(factor * per);
                stated.unit_text = Some(format!("{value} {target} per stored value"));
            }
            _ => {}
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gwyddion_headers_in_several_languages() {
        for lines in [
            [
                "# Channel: A b",
                "# Width: 12.34 µm",
                "# Height: 5678.9 nm",
                "# Value units: m",
            ],
            [
                "# Kanal: A b",
                "# Breite: 12.34 µm",
                "# Höhe: 5678.9 nm",
                "# Value units: m",
            ],
            // A language not listed: read by position.
            [
                "# Kanaal: A b",
                "# Breedte: 12.34 µm",
                "# Hoogte: 5678.9 nm",
                "# Eenheid: m",
            ],
        ] {
            let mut s = Stated::default();
            gwyddion(&lines, &mut s).unwrap();
            assert_eq!(s.channel.as_deref(), Some("A b"));
            let (x, y) = s.size_m.unwrap();
            assert!((x - 12.34e-6).abs() < 1e-18 && (y - 5678.9e-9).abs() < 1e-18);
            assert_eq!(s.unit_m, Some(1.0));
        }
        let mut s = Stated::default();
        let err = gwyddion(
            &[
                "# Channel: P",
                "# Width: 1 µm",
                "# Height: 1 µm",
                "# Value units: deg",
            ],
            &mut s,
        )
        .unwrap_err();
        assert!(err.contains("'deg'"), "{err}");
        let mut s = Stated::default();
        gwyddion(&["# exported by something"], &mut s).unwrap();
        assert!(!s.any());
    }

    #[test]
    fn key_value_headers() {
        let mut s = Stated::default();
        for line in [
            "h=305 w=75",
            "pixel size=3.69862e-007 m",
            "data unit=rad",
            "height conversion factor (-> m)=2.91818e-008",
        ] {
            assert!(is_key_value(line));
            key_value(line, &mut s).unwrap();
        }
        assert_eq!(s.shape, (Some(305), Some(75)));
        assert_eq!(s.pixel_m, Some(3.69862e-7));
        assert_eq!(s.unit_m, Some(2.91818e-8));
        assert!(!is_key_value("1.0 2.0 3.0"));
        assert!(key_value("h=0", &mut s).is_err());
        assert!(key_value("pixel size=3 V", &mut s).is_err());
    }
}
