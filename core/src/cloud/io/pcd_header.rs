//! The PCD header (versions 0.5 to 0.7): fields with their size, type and count, the
//! organisation (`WIDTH`, `HEIGHT`, `POINTS`), the `VIEWPOINT` and the data encoding.

use super::error::{CloudIoError, CloudIoErrorKind, Location, excerpt};
use super::scalar::ScalarType;
use super::text_lines::TextLines;

/// Body encoding of a PCD file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum PcdData {
    Ascii,
    Binary,
    BinaryCompressed,
}

/// A field: `COUNT` values of one type per point.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct PcdField {
    pub(crate) name: String,
    pub(crate) ty: ScalarType,
    pub(crate) count: u64,
}

/// A parsed header.
#[derive(Debug, Clone)]
pub(crate) struct PcdHeader {
    pub(crate) fields: Vec<PcdField>,
    pub(crate) width: u64,
    pub(crate) height: u64,
    pub(crate) points: u64,
    /// `tx ty tz qw qx qy qz`.
    pub(crate) viewpoint: Option<[f64; 7]>,
    pub(crate) data: PcdData,
    /// Byte offset of the body.
    pub(crate) body_offset: usize,
    /// Line number of the first body line (ASCII).
    pub(crate) body_line: usize,
    /// Line of the `DATA` keyword.
    pub(crate) data_line: usize,
}

impl PcdHeader {
    /// Bytes per binary record, and values per ASCII record (`None` on overflow).
    pub(crate) fn record_size(&self) -> Option<(u64, u64)> {
        let mut bytes = 0u64;
        let mut values = 0u64;
        for f in &self.fields {
            bytes = bytes.checked_add((f.ty.size() as u64).checked_mul(f.count)?)?;
            values = values.checked_add(f.count)?;
        }
        Some((bytes, values))
    }
}

fn header_error(line: usize, msg: String) -> CloudIoError {
    CloudIoError::at(Location::Line(line), CloudIoErrorKind::Header(msg))
}

fn parse_u64(line: usize, key: &str, v: &str) -> Result<u64, CloudIoError> {
    v.parse::<u64>().map_err(|_| {
        header_error(
            line,
            format!("{key} value `{}` is not a non-negative integer", excerpt(v)),
        )
    })
}

/// One value per field, or an error naming the keyword.
fn list<T>(
    entry: Option<(usize, Vec<String>)>,
    key: &str,
    n: usize,
    parse: impl Fn(usize, &str) -> Result<T, CloudIoError>,
) -> Result<Option<Vec<T>>, CloudIoError> {
    let Some((line, values)) = entry else {
        return Ok(None);
    };
    if values.len() != n {
        return Err(header_error(
            line,
            format!("{key} has {} values but FIELDS has {n}", values.len()),
        ));
    }
    values
        .iter()
        .map(|v| parse(line, v))
        .collect::<Result<Vec<_>, _>>()
        .map(Some)
}

/// A header line's keyword's line number and values, if the header has it.
type Entry = Option<(usize, Vec<String>)>;

/// The header's keywords before `DATA`, in the order of [`HeaderLines::entries`].
const KEYS: [&str; 9] = [
    "VERSION",
    "FIELDS",
    "SIZE",
    "TYPE",
    "COUNT",
    "WIDTH",
    "HEIGHT",
    "VIEWPOINT",
    "POINTS",
];

/// The header's lines up to and with `DATA`, each keyword at most once.
struct HeaderLines {
    /// The line of each of [`KEYS`], if present.
    entries: [Entry; 9],
    /// The body's encoding.
    data: PcdData,
    /// Line of the `DATA` keyword.
    data_line: usize,
}

/// Parses the header at the start of `bytes`.
pub(crate) fn parse_pcd_header(bytes: &[u8]) -> Result<PcdHeader, CloudIoError> {
    let mut lines = TextLines::new(bytes, 0, 1);
    let HeaderLines {
        entries,
        data,
        data_line,
    } = header_lines(&mut lines)?;
    let [
        _version,
        fields,
        sizes,
        types,
        counts,
        width,
        height,
        viewpoint,
        points,
    ] = entries;
    let fields = fields_of(fields, sizes, types, counts, data_line)?;
    let (width, height, points) = organisation(&width, &height, &points, data_line)?;
    let viewpoint = viewpoint_of(viewpoint)?;
    Ok(PcdHeader {
        fields,
        width,
        height,
        points,
        viewpoint,
        data,
        body_offset: lines.pos(),
        body_line: lines.line(),
        data_line,
    })
}

/// Reads the header's lines up to `DATA` (comments and blank lines skipped; `COLUMNS` is
/// `FIELDS`): the first keyword line must be one of [`KEYS`], the version 0.5 to 0.7.
fn header_lines(lines: &mut TextLines<'_>) -> Result<HeaderLines, CloudIoError> {
    let mut seen_keyword = false;
    let mut entries: [Entry; 9] = Default::default();
    loop {
        let Some(next) = lines.next_text() else {
            return Err(CloudIoError::at(
                Location::Line(lines.line()),
                CloudIoErrorKind::MissingHeaderEnd {
                    format: "PCD",
                    expected: "DATA",
                },
            ));
        };
        let (n, text) = next?;
        let text = text.trim();
        if text.is_empty() || text.starts_with('#') {
            continue;
        }
        let mut tokens = text.split_ascii_whitespace();
        let keyword = tokens.next().unwrap_or_default().to_ascii_uppercase();
        let args: Vec<String> = tokens.map(str::to_owned).collect();
        if keyword == "DATA" {
            return Ok(HeaderLines {
                entries,
                data: data_encoding(n, &args)?,
                data_line: n,
            });
        }
        let key = if keyword == "COLUMNS" {
            "FIELDS"
        } else {
            keyword.as_str()
        };
        let Some(slot) = KEYS.iter().position(|k| *k == key) else {
            return Err(unknown_keyword(n, text, &keyword, seen_keyword));
        };
        seen_keyword = true;
        if key == "VERSION" {
            check_version(n, &args)?;
        }
        if entries[slot].is_some() {
            return Err(header_error(n, format!("second {key} line")));
        }
        entries[slot] = Some((n, args));
    }
}

/// The encoding `DATA` names on line `n`.
fn data_encoding(n: usize, args: &[String]) -> Result<PcdData, CloudIoError> {
    match args.first().map(|a| a.to_ascii_lowercase()).as_deref() {
        Some("ascii") => Ok(PcdData::Ascii),
        Some("binary") => Ok(PcdData::Binary),
        Some("binary_compressed") => Ok(PcdData::BinaryCompressed),
        _ => Err(header_error(
            n,
            "DATA must be ascii, binary or binary_compressed".into(),
        )),
    }
}

/// The error of an unknown keyword on line `n`: not a PCD file if no keyword came before.
fn unknown_keyword(n: usize, text: &str, keyword: &str, seen_keyword: bool) -> CloudIoError {
    if !seen_keyword {
        return CloudIoError::at(
            Location::Line(n),
            CloudIoErrorKind::BadMagic {
                format: "PCD",
                detail: format!(
                    "expected a VERSION or FIELDS line, found `{}`",
                    excerpt(text)
                ),
            },
        );
    }
    header_error(n, format!("unknown header keyword `{}`", excerpt(keyword)))
}

/// Checks the `VERSION` on line `n`: 0.5 to 0.7 are read.
fn check_version(n: usize, args: &[String]) -> Result<(), CloudIoError> {
    if matches!(
        args.first().map(String::as_str),
        Some("0.7" | ".7" | "0.6" | ".6" | "0.5" | ".5")
    ) {
        return Ok(());
    }
    Err(CloudIoError::at(
        Location::Line(n),
        CloudIoErrorKind::Unsupported(format!(
            "PCD VERSION `{}` (0.5 to 0.7 are read)",
            excerpt(&args.join(" "))
        )),
    ))
}

/// The error of a keyword missing before `DATA` (on `data_line`).
fn missing(data_line: usize, key: &str) -> CloudIoError {
    header_error(data_line, format!("no {key} line before DATA"))
}

/// The fields from `FIELDS`, `SIZE`, `TYPE` and `COUNT` (1 each without it).
fn fields_of(
    fields: Entry,
    sizes: Entry,
    types: Entry,
    counts: Entry,
    data_line: usize,
) -> Result<Vec<PcdField>, CloudIoError> {
    let Some((_, names)) = fields else {
        return Err(missing(data_line, "FIELDS"));
    };
    let n = names.len();
    let sizes = list(sizes, "SIZE", n, |l, v| {
        v.parse::<usize>()
            .map_err(|_| header_error(l, format!("SIZE value `{}` is not an integer", excerpt(v))))
    })?
    .ok_or_else(|| missing(data_line, "SIZE"))?;
    let types = list(types, "TYPE", n, |_, v| Ok(v.to_owned()))?
        .ok_or_else(|| missing(data_line, "TYPE"))?;
    let counts = list(counts, "COUNT", n, |l, v| {
        let c = parse_u64(l, "COUNT", v)?;
        if c == 0 {
            return Err(header_error(l, "COUNT values must be at least 1".into()));
        }
        Ok(c)
    })?
    .unwrap_or_else(|| vec![1; n]);
    let mut out_fields = Vec::with_capacity(n);
    for (((name, size), ty), count) in names.into_iter().zip(sizes).zip(types).zip(counts) {
        let Some(t) = ScalarType::from_pcd(&ty, size) else {
            return Err(header_error(
                data_line,
                format!(
                    "field `{}`: TYPE {} with SIZE {size} is not a known type",
                    excerpt(&name),
                    excerpt(&ty)
                ),
            ));
        };
        out_fields.push(PcdField { name, ty: t, count });
    }
    Ok(out_fields)
}

/// The single integer of a `WIDTH`, `HEIGHT` or `POINTS` line, if the header has it.
fn single(e: &Entry, key: &str) -> Result<Option<u64>, CloudIoError> {
    match e {
        None => Ok(None),
        Some((l, v)) => match &v[..] {
            [x] => parse_u64(*l, key, x).map(Some),
            _ => Err(header_error(*l, format!("{key} takes one value"))),
        },
    }
}

/// `(width, height, points)`: `HEIGHT` 1 and `POINTS` `WIDTH × HEIGHT` by default,
/// `WIDTH` `POINTS` for a height of 1; they must agree.
fn organisation(
    width: &Entry,
    height: &Entry,
    points: &Entry,
    data_line: usize,
) -> Result<(u64, u64, u64), CloudIoError> {
    let w = single(width, "WIDTH")?;
    let h = single(height, "HEIGHT")?.unwrap_or(1);
    let p = single(points, "POINTS")?;
    let (width, points) = match (w, p) {
        (Some(w), Some(p)) => (w, p),
        (Some(w), None) => (
            w,
            w.checked_mul(h)
                .ok_or_else(|| header_error(data_line, "WIDTH × HEIGHT overflows".into()))?,
        ),
        (None, Some(p)) if h == 1 => (p, p),
        _ => return Err(missing(data_line, "WIDTH")),
    };
    if width.checked_mul(h) != Some(points) {
        return Err(header_error(
            data_line,
            format!("WIDTH × HEIGHT = {width} × {h} does not equal POINTS = {points}"),
        ));
    }
    Ok((width, h, points))
}

/// The `VIEWPOINT` `tx ty tz qw qx qy qz`, if the header has one.
fn viewpoint_of(viewpoint: Entry) -> Result<Option<[f64; 7]>, CloudIoError> {
    let Some((l, v)) = viewpoint else {
        return Ok(None);
    };
    let vals: Option<Vec<f64>> = v.iter().map(|x| x.parse::<f64>().ok()).collect();
    match vals.as_deref() {
        Some(&[a, b, c, d, e, f, g]) if [a, b, c, d, e, f, g].iter().all(|x| x.is_finite()) => {
            Ok(Some([a, b, c, d, e, f, g]))
        }
        _ => Err(header_error(
            l,
            "VIEWPOINT needs 7 finite numbers: tx ty tz qw qx qy qz".into(),
        )),
    }
}
