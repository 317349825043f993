//! Inputs by URL (`http://`; `s3://` against moto's S3 server in
//! `python/tests/test_object_storage.py`): a small HTTP/1.1 server written here from RFC 9110
//! (HEAD, GET, `Range: bytes=…` answered 206 with `Content-Range`, or ignored) serves a folder on
//! loopback; a TIFF and OME-Zarr stores of both versions analyse from it with the same numbers as
//! from disk, also when the first connections are cut in the middle of a response or the server
//! ignores byte ranges; a missing object and a server that cuts every connection give one line
//! naming the URL and no output.

use std::io::{BufRead, BufReader, Write};
use std::net::{Shutdown, TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

use super::ome_zarr::{analyze, numbers, planes, store_v2, store_v3, tiff};
use crate::common::{run, stderr};

/// How the server misbehaves.
#[derive(Clone, Copy)]
struct Faults {
    /// Cut this many connections (the first ones) after `after` bytes of response.
    cut: usize,
    /// Cut every connection.
    cut_all: bool,
    after: usize,
    /// Answer every GET with the whole file (200), ignoring `Range`.
    ignore_range: bool,
    /// Wait this long before answering each request (a distant server's round trip).
    delay_ms: u64,
}

const HONEST: Faults = Faults {
    cut: 0,
    cut_all: false,
    after: 0,
    ignore_range: false,
    delay_ms: 0,
};

/// A server on loopback: its base URL, how many connections it has cut, and the most GET
/// requests it has answered at the same time.
struct Served {
    base: String,
    cut: Arc<AtomicUsize>,
    most_at_once: Arc<AtomicUsize>,
}

/// Serve `root` on a loopback port.
fn serve(root: &Path, faults: Faults) -> Served {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let url = format!("http://{}", listener.local_addr().unwrap());
    let cut = Arc::new(AtomicUsize::new(0));
    let most_at_once = Arc::new(AtomicUsize::new(0));
    let active = Arc::new(AtomicUsize::new(0));
    let (root, counter) = (root.to_path_buf(), cut.clone());
    let most = most_at_once.clone();
    std::thread::spawn(move || {
        for stream in listener.incoming().flatten() {
            let kill = faults.cut_all
                || counter
                    .fetch_update(Ordering::SeqCst, Ordering::SeqCst, |c| {
                        (c < faults.cut).then_some(c + 1)
                    })
                    .is_ok();
            let root = root.clone();
            let gets = (active.clone(), most.clone());
            std::thread::spawn(move || {
                let _ = connection(stream, &root, faults, kill, gets);
            });
        }
    });
    Served {
        base: url,
        cut,
        most_at_once,
    }
}

/// Answer the requests of one connection (keep-alive) until the client closes it.
fn connection(
    stream: TcpStream,
    root: &Path,
    faults: Faults,
    kill: bool,
    (active, most): (Arc<AtomicUsize>, Arc<AtomicUsize>),
) -> std::io::Result<()> {
    let mut reader = BufReader::new(stream.try_clone()?);
    let mut out = stream;
    let mut sent = 0usize;
    loop {
        let mut request = String::new();
        loop {
            let mut line = String::new();
            if reader.read_line(&mut line)? == 0 {
                return Ok(());
            }
            if line == "\r\n" {
                break;
            }
            request.push_str(&line);
        }
        let mut words = request.split_whitespace();
        let (method, target) = (words.next().unwrap_or(""), words.next().unwrap_or("/"));
        // GETs being answered now (this one included), counted while it waits and is sent.
        let _answering = (method == "GET").then(|| {
            let now = active.fetch_add(1, Ordering::SeqCst) + 1;
            most.fetch_max(now, Ordering::SeqCst);
            Decrement(active.clone())
        });
        std::thread::sleep(std::time::Duration::from_millis(faults.delay_ms));
        let range = request.lines().find_map(|l| {
            let (name, value) = l.split_once(':')?;
            name.eq_ignore_ascii_case("range")
                .then(|| value.trim().trim_start_matches("bytes=").to_string())
        });
        let path: PathBuf = root.join(target.split('?').next().unwrap().trim_start_matches('/'));
        let Ok(body) = std::fs::read(&path)
            .map_err(|_| ())
            .and_then(|b| match path.is_file() {
                true => Ok(b),
                false => Err(()),
            })
        else {
            out.write_all(b"HTTP/1.1 404 Not Found\r\nContent-Length: 0\r\n\r\n")?;
            continue;
        };
        let n = body.len();
        let (status, part, extra) = match (range, faults.ignore_range || method == "HEAD") {
            (Some(r), false) => {
                let (a, b) = r.split_once('-').unwrap();
                let (start, end) = match (a.parse::<usize>(), b.parse::<usize>()) {
                    (Ok(a), Ok(b)) => (a, (b + 1).min(n)),
                    (Ok(a), Err(_)) => (a, n),
                    (Err(_), Ok(suffix)) => (n.saturating_sub(suffix), n),
                    _ => (0, n),
                };
                let extra = format!("Content-Range: bytes {start}-{}/{n}\r\n", end - 1);
                ("206 Partial Content", &body[start..end], extra)
            }
            _ => ("200 OK", &body[..], String::new()),
        };
        let head = format!(
            "HTTP/1.1 {status}\r\nContent-Length: {}\r\n{extra}\r\n",
            part.len()
        );
        out.write_all(head.as_bytes())?;
        if method == "HEAD" {
            continue;
        }
        if kill && sent + part.len() > faults.after {
            let keep = faults.after.saturating_sub(sent);
            out.write_all(&part[..keep])?;
            return out.shutdown(Shutdown::Both);
        }
        out.write_all(part)?;
        sent += part.len();
    }
}

/// Lowers a count when dropped.
struct Decrement(Arc<AtomicUsize>);

impl Drop for Decrement {
    fn drop(&mut self) {
        self.0.fetch_sub(1, Ordering::SeqCst);
    }
}

/// The URL of `file` below the served folder `root`.
fn url_of(base: &str, root: &Path, file: &Path) -> PathBuf {
    let rel = file.strip_prefix(root).unwrap().to_str().unwrap();
    PathBuf::from(format!("{base}/{rel}"))
}

#[test]
fn files_and_stores_by_url_analyse_as_on_disk_through_cut_connections() {
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path().join("served");
    std::fs::create_dir_all(&root).unwrap();
    let planes = planes();
    let inputs = [
        tiff(&root, &planes),
        store_v2(&root, &planes),
        store_v3(&root, &planes),
    ];
    for (k, input) in inputs.iter().enumerate() {
        let reference = numbers(&analyze(input, &dir.path().join(format!("disk{k}")), &[]));
        let cuts = Faults {
            cut: 3,
            after: 700,
            ..HONEST
        };
        let no_ranges = Faults {
            ignore_range: true,
            ..HONEST
        };
        for (j, faults) in [HONEST, cuts, no_ranges].into_iter().enumerate() {
            let served = serve(&root, faults);
            let (base, cut) = (served.base, served.cut);
            let url = url_of(&base, &root, input);
            let out = dir.path().join(format!("url{k}-{j}"));
            assert_eq!(
                numbers(&analyze(&url, &out, &[])),
                reference,
                "{}",
                url.display()
            );
            if j == 1 {
                assert_eq!(cut.load(Ordering::SeqCst), 3, "{}", url.display());
            }
        }
    }
    // A reader fed by URL gives the same planes (Python and napari read through it).
    let base = serve(&root, HONEST).base;
    let mut local = contactscope_formats::microscopy::MicroscopyFile::open(&inputs[0]).unwrap();
    let mut remote =
        contactscope_formats::microscopy::MicroscopyFile::open(&url_of(&base, &root, &inputs[0]))
            .unwrap();
    let index = contactscope_formats::microscopy::PlaneIndex::tzc(0, 2, 0);
    let (a, b) = (
        local.read_plane(0, &index).unwrap(),
        remote.read_plane(0, &index).unwrap(),
    );
    assert_eq!(format!("{:?}", a.samples), format!("{:?}", b.samples));
}

#[test]
fn a_missing_object_or_a_dead_server_is_one_line_and_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path().join("served");
    std::fs::create_dir_all(&root).unwrap();
    let input = tiff(&root, &planes());
    let base = serve(&root, HONEST).base;
    let dead = Faults {
        cut_all: true,
        after: 100,
        ..HONEST
    };
    let dead_base = serve(&root, dead).base;
    let missing = format!("{base}/nothing-here.tif");
    let cut = url_of(&dead_base, &root, &input);
    let cases = [
        (missing.as_str(), "no such object (HTTP 404)"),
        (cut.to_str().unwrap(), "(5 tries)"),
        ("http://127.0.0.1:1/ramp.tif", "(5 tries)"),
    ];
    for (url, what) in cases {
        let out = dir.path().join("out");
        let o = run(&[
            "analyze",
            url,
            "--forces",
            "4mN..400mN:4",
            "--out",
            out.to_str().unwrap(),
        ]);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{url}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(err.contains(url) && err.contains(what), "{err}");
        assert!(!out.exists());
    }
    // A plane none of whose chunks the server has is refused, as on disk (never written, or an
    // incomplete upload), not read as the fill value.
    let store = super::ome_zarr::store_v3(&root, &planes());
    std::fs::remove_dir_all(store.join("0/c/1")).unwrap();
    let url = url_of(&base, &root, &store);
    let out = dir.path().join("out");
    let o = run(&[
        "analyze",
        url.to_str().unwrap(),
        "--load-axis",
        "t",
        "--forces",
        "4mN..400mN:4",
        "--out",
        out.to_str().unwrap(),
    ]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("none of its chunks"), "{err}");
    assert!(!out.exists());
    // Outputs are local: a URL as --out is refused before any work.
    let o = run(&[
        "analyze",
        url_of(&base, &root, &input).to_str().unwrap(),
        "--forces",
        "4mN..400mN:4",
        "--out",
        "s3://bucket/results",
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("not to object storage"),
        "{}",
        stderr(&o)
    );
    // An endpoint that is no http(s) URL is a usage error (exit 2), before anything is read.
    let o = run(&[
        "info",
        "s3://lab/ramp.tif",
        "--endpoint-url",
        "ftp://h:9000",
    ]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.starts_with("contactscope: error: --endpoint-url") && err.lines().count() == 1);
}

/// A square plane of `side` pixels: a bright disc of radius `r` on a dim background, with a
/// fixed pattern of noise that differs from plane `t` to plane.
fn disc(side: usize, r: f64, t: usize) -> Vec<u16> {
    let c = (side as f64 - 1.0) / 2.0;
    (0..side * side)
        .map(|i| {
            let (x, y) = ((i % side) as f64 - c, (i / side) as f64 - c);
            let pattern = ((i * 7919 + t * 104_729) % 61) as u16;
            pattern + if x * x + y * y < r * r { 1800 } else { 120 }
        })
        .collect()
}

/// A file of several of the reader's blocks (4 MiB), read in order: the blocks after the one
/// read are fetched at the same time (each request waits 40 ms here, as a distant server's
/// would), and every number is the same as from disk, also through cut connections. Reading
/// one block at a time, `info` (one thread walking the headers) never had two requests out.
#[test]
fn a_file_read_in_order_is_fetched_ahead_on_parallel_connections() {
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path().join("served");
    std::fs::create_dir_all(&root).unwrap();
    // Six 1024 × 1024 planes of 16 bits (12 MiB, three blocks).
    let (w, h) = (1024usize, 1024usize);
    let planes: Vec<Vec<u16>> = (0..6)
        .map(|t| disc(w, 100.0 + 60.0 * t as f64, t))
        .collect();
    let refs: Vec<&[u16]> = planes.iter().map(Vec::as_slice).collect();
    let bytes =
        contactscope_formats::tiff::encode_u16_stack(&refs, w, h, Some((2e-7, 2e-7)), "").unwrap();
    assert!(bytes.len() > 12 << 20);
    let input = root.join("big.tif");
    std::fs::write(&input, bytes).unwrap();
    let analyze = |path: &Path, out: &str| {
        let out = dir.path().join(out);
        let args = [
            "analyze",
            path.to_str().unwrap(),
            "--forces",
            "4mN..400mN:6",
            "--out",
            out.to_str().unwrap(),
            "--quiet",
        ];
        crate::common::run_ok(&args);
        std::fs::read_to_string(out.join("areas.csv")).unwrap()
    };
    let reference = analyze(&input, "disk");
    let far = Faults {
        delay_ms: 40,
        ..HONEST
    };
    let served = serve(&root, far);
    let url = url_of(&served.base, &root, &input);
    let o = run(&["info", url.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        served.most_at_once.load(Ordering::SeqCst) >= 2,
        "info asked for one block at a time"
    );
    // The areas table names its input: compare the rows below the header only.
    let rows = |csv: &String| -> Vec<String> {
        csv.lines()
            .skip(1)
            .map(|l| l.split_once(',').map_or("", |(_, rest)| rest).to_string())
            .collect()
    };
    assert_eq!(rows(&analyze(&url, "far")), rows(&reference));
    let cuts = Faults {
        cut: 4,
        after: 1 << 20,
        ..far
    };
    let served = serve(&root, cuts);
    let url = url_of(&served.base, &root, &input);
    assert_eq!(rows(&analyze(&url, "cut")), rows(&reference));
    assert_eq!(served.cut.load(Ordering::SeqCst), 4);
}

/// An OME-Zarr store on a server 40 ms away, read plane after plane: the next planes' chunks
/// are fetched while one is read (more requests out at once than the analysis has threads),
/// and the threshold is the one read from disk. Reading one chunk per request on each thread,
/// at most two were ever out.
#[test]
fn a_store_read_plane_after_plane_fetches_the_next_chunks_ahead() {
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path().join("served");
    let store = root.join("ramp.ome.zarr");
    std::fs::create_dir_all(store.join("0")).unwrap();
    let (n, side) = (16usize, 64usize);
    let write = |path: &Path, text: &str| std::fs::write(path, text).unwrap();
    write(&store.join(".zgroup"), r#"{"zarr_format": 2}"#);
    write(
        &store.join(".zattrs"),
        r#"{"multiscales": [{"version": "0.4", "axes": [{"name": "t", "type": "time"},
            {"name": "y", "type": "space", "unit": "micrometer"},
            {"name": "x", "type": "space", "unit": "micrometer"}],
            "datasets": [{"path": "0", "coordinateTransformations":
            [{"type": "scale", "scale": [1.0, 0.2, 0.2]}]}]}]}"#,
    );
    write(
        &store.join("0/.zarray"),
        &format!(
            r#"{{"zarr_format": 2, "shape": [{n}, {side}, {side}], "chunks": [1, {side}, {side}],
            "dtype": "<u2", "compressor": null, "fill_value": 0, "order": "C", "filters": null,
            "dimension_separator": "/"}}"#
        ),
    );
    for t in 0..n {
        let bytes: Vec<u8> = disc(side, 4.0 + 1.5 * t as f64, t)
            .into_iter()
            .flat_map(u16::to_le_bytes)
            .collect();
        std::fs::create_dir_all(store.join(format!("0/{t}/0"))).unwrap();
        std::fs::write(store.join(format!("0/{t}/0/0")), bytes).unwrap();
    }
    let threshold = |path: &Path| {
        let o = crate::common::run_ok(&["threshold", path.to_str().unwrap(), "--load-axis", "t"]);
        crate::common::stdout(&o)
    };
    let reference = threshold(&store);
    let served = serve(
        &root,
        Faults {
            delay_ms: 40,
            ..HONEST
        },
    );
    let url = url_of(&served.base, &root, &store);
    assert_eq!(
        threshold(&url),
        reference.replace(store.to_str().unwrap(), url.to_str().unwrap())
    );
    let most = served.most_at_once.load(Ordering::SeqCst);
    assert!(most >= 3, "at most {most} requests out at once");
}
