//! The exchange format (`docs/exchange-format.md`): a problem directory with `A.mtx`,
//! `N.mtx`, `T.mtx` (Matrix Market), `f0.txt`, `f1.txt`, optional `gap.txt`, and
//! `meta.json`.
//!
//! Reading rules (every violation is an [`Error::Io`] whose one-line message names the file
//! and, where there is one, the 1-based line; it quotes at most a short excerpt of the
//! offending text):
//! - Matrix Market: the header `%%MatrixMarket matrix coordinate|array real|integer
//!   general|symmetric` (case-insensitive), then comment lines (`%`) and blank lines, then
//!   the size line. `coordinate`: the size line `rows cols entries`, then exactly `entries`
//!   lines `i j value` with 1-based indices; **repeated entries are summed** (assembly
//!   convention, the same as the C ABI's CSR input). `array`: the size line `rows cols`,
//!   then the values one a line, column by column (dense; exact zeros are not stored).
//!   A `symmetric` file must be square; in coordinate form it stores one triangle only
//!   (the lower one, as the standard says, or the upper one), in array form the lower
//!   triangle with the diagonal, column by column; it is expanded to full storage.
//!   `integer` values are signed decimal integers, `real` ones finite numbers (`1.5D+00`
//!   too). `pattern`, `complex`, `hermitian` and `skew-symmetric` files are refused with
//!   a message saying why.
//! - Vector files: one number a line (blank lines ignored), finite, exactly `n` (`f0`,
//!   `f1`) or `p` (`gap`) of them.
//! - Compression: any of these files may instead be given gzip-compressed as `NAME.gz`
//!   (`A.mtx.gz`, …); it is read when `NAME` itself does not exist (the plain file wins
//!   when both do). Errors then name the `.gz` file and count the lines of its text.
//! - `meta.json`: an object with `n`, `p` (positive integers), `F` (a number ≥ 0 or an
//!   array of `p` numbers ≥ 0), `alpha_start`, `alpha_end` (finite numbers); any other keys
//!   are kept in [`CaseData::meta`] and written back by [`CaseData::write_dir`]. `n` and `p`
//!   must agree with the matrices.

use std::fmt::Write as _;
use std::path::Path as FsPath;

use crate::{Error, Result};
use fricont::load::Load;
use fricont::problem::{CsrMatrix, Problem, ProblemBuilder, Storage};

/// A problem in the exchange format, in memory.
#[derive(Debug, Clone, PartialEq)]
pub struct CaseData {
    /// Stiffness, full storage (a `symmetric` Matrix Market file is expanded).
    pub a: CsrMatrix,
    /// Normal contact matrix (p×n).
    pub n_mat: CsrMatrix,
    /// Tangential contact matrix (p×n).
    pub t_mat: CsrMatrix,
    /// Load at α = 0 (n).
    pub f0: Vec<f64>,
    /// Load per unit α (n).
    pub f1: Vec<f64>,
    /// Gap (p), if given.
    pub gap: Option<Vec<f64>>,
    /// Friction: one value or p values.
    pub friction: Vec<f64>,
    /// Start of the α window.
    pub alpha_start: f64,
    /// End of the α window.
    pub alpha_end: f64,
    /// The whole `meta.json` object (descriptive keys kept).
    pub meta: serde_json::Value,
}

impl CaseData {
    /// Reads a problem directory. Errors: [`crate::Error::Io`] with the file name and the
    /// line of the first problem (missing file, bad Matrix Market header or size line,
    /// wrong number of entries, index out of range, non-numeric or non-finite value,
    /// `meta.json` keys missing or of the wrong type, `n`/`p` disagreeing with the
    /// matrices or vectors).
    pub fn read_dir(dir: &std::path::Path) -> Result<CaseData> {
        let meta_path = dir.join("meta.json");
        let (meta_path, meta_text) = read_text(&meta_path)?;
        let meta = parse_meta(&meta_path, &meta_text)?;

        let a = read_mtx(
            &dir.join("A.mtx"),
            Some((meta.n, meta.n)),
            "n x n (n from meta.json)",
        )?;
        let n_mat = read_mtx(
            &dir.join("N.mtx"),
            Some((meta.p, meta.n)),
            "p x n (from meta.json)",
        )?;
        let t_mat = read_mtx(
            &dir.join("T.mtx"),
            Some((meta.p, meta.n)),
            "p x n (from meta.json)",
        )?;
        let f0 = read_vector(&dir.join("f0.txt"), meta.n, "n")?;
        let f1 = read_vector(&dir.join("f1.txt"), meta.n, "n")?;
        let gap_path = dir.join("gap.txt");
        let gap = if gap_path.exists() || dir.join("gap.txt.gz").exists() {
            Some(read_vector(&gap_path, meta.p, "p")?)
        } else {
            None
        };
        Ok(CaseData {
            a,
            n_mat,
            t_mat,
            f0,
            f1,
            gap,
            friction: meta.friction,
            alpha_start: meta.alpha_start,
            alpha_end: meta.alpha_end,
            meta: meta.value,
        })
    }

    /// Writes a problem directory (creating it and overwriting the files of the format).
    /// A, N and T are written as `general` coordinate files with 1-based indices; every
    /// number is written in shortest round-trip form, so [`CaseData::read_dir`] gives back
    /// exactly the same data. `meta.json` gets `n`, `p`, `F` (a number when one value is
    /// stored, an array otherwise), `alpha_start`, `alpha_end` from the fields, and every
    /// other key of [`CaseData::meta`]. `gap.txt` is written only when a gap is present
    /// (a stale `gap.txt` is removed otherwise). Errors: [`Error::Io`] for a failed write,
    /// [`Error::Core`] (a `fricont::Error::Dimension`) when the fields disagree with each
    /// other.
    pub fn write_dir(&self, dir: &std::path::Path) -> Result<()> {
        self.check_dims()?;
        std::fs::create_dir_all(dir)
            .map_err(|e| Error::Io(format!("cannot create {}: {e}", dir.display())))?;
        write_text(&dir.join("A.mtx"), &mtx_text(&self.a))?;
        write_text(&dir.join("N.mtx"), &mtx_text(&self.n_mat))?;
        write_text(&dir.join("T.mtx"), &mtx_text(&self.t_mat))?;
        write_text(&dir.join("f0.txt"), &vector_text(&self.f0))?;
        write_text(&dir.join("f1.txt"), &vector_text(&self.f1))?;
        let gap_path = dir.join("gap.txt");
        match &self.gap {
            Some(g) => write_text(&gap_path, &vector_text(g))?,
            None => {
                if gap_path.exists() {
                    std::fs::remove_file(&gap_path).map_err(|e| {
                        Error::Io(format!("cannot remove {}: {e}", gap_path.display()))
                    })?;
                }
            }
        }
        let mut obj = match &self.meta {
            serde_json::Value::Object(m) => m.clone(),
            _ => serde_json::Map::new(),
        };
        obj.insert("n".into(), self.a.nrows().into());
        obj.insert("p".into(), self.n_mat.nrows().into());
        let f = if self.friction.len() == 1 {
            json_number(self.friction[0])
        } else {
            serde_json::Value::Array(self.friction.iter().map(|&x| json_number(x)).collect())
        };
        obj.insert("F".into(), f);
        obj.insert("alpha_start".into(), json_number(self.alpha_start));
        obj.insert("alpha_end".into(), json_number(self.alpha_end));
        let text = serde_json::to_string_pretty(&serde_json::Value::Object(obj))
            .map_err(|e| Error::Io(format!("cannot serialise meta.json: {e}")))?;
        write_text(&dir.join("meta.json"), &(text + "\n"))
    }

    /// Number of dofs `n` (rows of A).
    pub fn n(&self) -> usize {
        self.a.nrows()
    }

    /// Number of contact nodes `p` (rows of N).
    pub fn p(&self) -> usize {
        self.n_mat.nrows()
    }

    /// Builds the [`Problem`] (A in full storage, F, gap, and `r` if given, else the
    /// default of [`Problem::default_r`]). This is the set-up cost: validation, the sparse
    /// Cholesky of A and the Delassus operator W. Errors: those of
    /// [`ProblemBuilder::build`] (A not SPD, B rank-deficient, F < 0, r ≤ 0, …).
    pub fn problem(&self, r: Option<f64>) -> Result<Problem> {
        let mut b = self.builder();
        if let Some(r) = r {
            b = b.r(r);
        }
        Ok(b.build()?)
    }

    /// The builder of [`CaseData::problem`] before `build`, for settings the files do not
    /// hold (r, threads). Copies A, N, T (the case keeps its own).
    pub fn builder(&self) -> ProblemBuilder {
        let mut b = ProblemBuilder::new(
            self.a.clone(),
            Storage::Full,
            self.n_mat.clone(),
            self.t_mat.clone(),
        );
        b = if self.friction.len() == 1 {
            b.friction_uniform(self.friction[0])
        } else {
            b.friction(self.friction.clone())
        };
        if let Some(g) = &self.gap {
            b = b.gap(g.clone());
        }
        b
    }

    /// The affine load `f(α) = f0 + α f1` of the files. Errors: lengths differ, non-finite
    /// entries (see [`Load::affine`]).
    pub fn load(&self) -> Result<Load> {
        Ok(Load::affine(self.f0.clone(), self.f1.clone())?)
    }

    fn check_dims(&self) -> Result<()> {
        let n = self.a.nrows();
        let p = self.n_mat.nrows();
        let mut bad = Vec::new();
        if self.a.ncols() != n {
            bad.push(format!("A is {}x{}, not square", n, self.a.ncols()));
        }
        if self.n_mat.ncols() != n {
            bad.push(format!("N has {} columns, n = {n}", self.n_mat.ncols()));
        }
        if self.t_mat.nrows() != p || self.t_mat.ncols() != n {
            bad.push(format!(
                "T is {}x{}, expected {p}x{n}",
                self.t_mat.nrows(),
                self.t_mat.ncols()
            ));
        }
        if self.f0.len() != n || self.f1.len() != n {
            bad.push(format!(
                "f0, f1 have {}, {} entries, n = {n}",
                self.f0.len(),
                self.f1.len()
            ));
        }
        if let Some(g) = &self.gap
            && g.len() != p
        {
            bad.push(format!("gap has {} entries, p = {p}", g.len()));
        }
        if self.friction.len() != 1 && self.friction.len() != p {
            bad.push(format!(
                "friction has {} entries, expected 1 or p = {p}",
                self.friction.len()
            ));
        }
        if bad.is_empty() {
            Ok(())
        } else {
            Err(fricont::Error::Dimension(bad.join("; ")).into())
        }
    }
}

/// The required keys of `meta.json`, parsed.
struct Meta {
    n: usize,
    p: usize,
    friction: Vec<f64>,
    alpha_start: f64,
    alpha_end: f64,
    value: serde_json::Value,
}

fn io_err(path: &FsPath, line: Option<usize>, msg: impl std::fmt::Display) -> Error {
    match line {
        Some(l) => Error::Io(format!("{}:{l}: {msg}", path.display())),
        None => Error::Io(format!("{}: {msg}", path.display())),
    }
}

/// Reads a text file; if `path` does not exist but `path.gz` does, that file is
/// decompressed instead (errors then name the `.gz` file; line numbers count lines of the
/// decompressed text).
fn read_text(path: &FsPath) -> Result<(std::path::PathBuf, String)> {
    if !path.exists() {
        let mut gz = path.as_os_str().to_owned();
        gz.push(".gz");
        let gz = std::path::PathBuf::from(gz);
        if gz.exists() {
            use std::io::Read as _;
            let file = std::fs::File::open(&gz)
                .map_err(|e| io_err(&gz, None, format!("cannot read: {e}")))?;
            let mut text = String::new();
            flate2::read::MultiGzDecoder::new(std::io::BufReader::new(file))
                .read_to_string(&mut text)
                .map_err(|e| io_err(&gz, None, format!("cannot decompress: {e}")))?;
            return Ok((gz, text));
        }
    }
    let text = std::fs::read_to_string(path)
        .map_err(|e| io_err(path, None, format!("cannot read: {e}")))?;
    Ok((path.to_path_buf(), text))
}

fn write_text(path: &FsPath, text: &str) -> Result<()> {
    std::fs::write(path, text).map_err(|e| io_err(path, None, format!("cannot write: {e}")))
}

fn json_number(x: f64) -> serde_json::Value {
    serde_json::Number::from_f64(x).map_or(serde_json::Value::Null, serde_json::Value::Number)
}

fn parse_meta(path: &FsPath, text: &str) -> Result<Meta> {
    let value: serde_json::Value = serde_json::from_str(text)
        .map_err(|e| io_err(path, Some(e.line()), format!("invalid JSON: {e}")))?;
    let Some(obj) = value.as_object() else {
        return Err(io_err(path, None, "expected a JSON object"));
    };
    let get = |key: &str| {
        obj.get(key)
            .ok_or_else(|| io_err(path, None, format!("missing required key \"{key}\"")))
    };
    let positive_int = |key: &str| -> Result<usize> {
        let v = get(key)?;
        // Integers, and floats with an integral value (1320.0, as some writers emit).
        let as_int = v.as_u64().or_else(|| {
            v.as_f64()
                .filter(|x| x.fract() == 0.0 && *x > 0.0 && *x < 9.007_199_254_740_992e15)
                .map(|x| x as u64)
        });
        match as_int {
            Some(x) if x > 0 => usize::try_from(x)
                .map_err(|_| io_err(path, None, format!("\"{key}\" = {x} is too large"))),
            _ => Err(io_err(
                path,
                None,
                format!(
                    "\"{key}\" must be a positive integer, found {}",
                    excerpt(&v.to_string())
                ),
            )),
        }
    };
    let finite = |key: &str, v: &serde_json::Value| -> Result<f64> {
        match v.as_f64() {
            Some(x) if x.is_finite() => Ok(x),
            _ => Err(io_err(
                path,
                None,
                format!(
                    "\"{key}\" must be a finite number, found {}",
                    excerpt(&v.to_string())
                ),
            )),
        }
    };
    let n = positive_int("n")?;
    let p = positive_int("p")?;
    let alpha_start = finite("alpha_start", get("alpha_start")?)?;
    let alpha_end = finite("alpha_end", get("alpha_end")?)?;
    let fv = get("F")?;
    let friction = match fv {
        serde_json::Value::Array(items) => {
            if items.len() != p {
                return Err(io_err(
                    path,
                    None,
                    format!("\"F\" has {} values, expected p = {p}", items.len()),
                ));
            }
            items
                .iter()
                .enumerate()
                .map(|(i, v)| finite(&format!("F[{}] (1-based)", i + 1), v))
                .collect::<Result<Vec<f64>>>()?
        }
        v => vec![finite("F", v)?],
    };
    if let Some(i) = friction.iter().position(|&f| f < 0.0) {
        return Err(io_err(
            path,
            None,
            format!(
                "friction must be >= 0, \"F\" value {} is {}",
                i + 1,
                friction[i]
            ),
        ));
    }
    Ok(Meta {
        n,
        p,
        friction,
        alpha_start,
        alpha_end,
        value,
    })
}

/// At most a short excerpt of an input text for a message: texts up to 40 characters as
/// they are, longer ones cut to their first 32 characters with the length in bytes (a
/// corrupt file may hold a line of megabytes; a message stays one short line).
fn excerpt(s: &str) -> String {
    const KEEP: usize = 32;
    if s.chars().nth(40).is_none() {
        return s.to_string();
    }
    let cut = s.char_indices().nth(KEEP).map_or(s.len(), |(k, _)| k);
    format!("{}… ({} bytes)", &s[..cut], s.len())
}

/// Parses a real number as written by C, Fortran (`1.5D+00` too) or Rust; rejects NaN/Inf.
fn parse_real(path: &FsPath, line: usize, tok: &str, what: &str) -> Result<f64> {
    let parsed = tok.parse::<f64>().ok().or_else(|| {
        if tok.contains(['d', 'D']) {
            tok.replace(['d', 'D'], "e").parse::<f64>().ok()
        } else {
            None
        }
    });
    match parsed {
        Some(x) if x.is_finite() => Ok(x),
        Some(x) => Err(io_err(
            path,
            Some(line),
            format!("{what} is {x} (only finite values are allowed)"),
        )),
        None => Err(io_err(
            path,
            Some(line),
            format!("{what} \"{}\" is not a number", excerpt(tok)),
        )),
    }
}

/// Parses the value of an `integer` Matrix Market file (a signed decimal integer).
fn parse_integer(path: &FsPath, line: usize, tok: &str) -> Result<f64> {
    tok.parse::<i64>().map(|v| v as f64).map_err(|_| {
        io_err(
            path,
            Some(line),
            format!(
                "value \"{}\" is not an integer (the header declares the field integer)",
                excerpt(tok)
            ),
        )
    })
}

fn parse_count(path: &FsPath, line: usize, tok: &str, what: &str) -> Result<usize> {
    tok.parse::<usize>().map_err(|_| {
        io_err(
            path,
            Some(line),
            format!("{what} \"{}\" is not a non-negative integer", excerpt(tok)),
        )
    })
}

/// Reads a Matrix Market file into full-storage CSR. `expect` (rows, cols), if given, is
/// checked against the size line (`expect_what` explains where it comes from).
fn read_mtx(path: &FsPath, expect: Option<(usize, usize)>, expect_what: &str) -> Result<CsrMatrix> {
    let (path, text) = read_text(path)?;
    parse_mtx(&path, &text, expect, expect_what)
}

/// The header every accepted Matrix Market file has (for messages).
const MM_HEADER: &str = "%%MatrixMarket matrix coordinate|array real|integer general|symmetric";

/// What a Matrix Market header declares (only the variants fricont reads).
struct MmHeader {
    /// `array` (dense, column-major) rather than `coordinate`.
    array: bool,
    /// Field `integer` rather than `real`.
    integer: bool,
    /// Symmetry `symmetric` rather than `general`.
    symmetric: bool,
}

/// Parses the header line; every unsupported variant is a one-line error saying why.
fn parse_mm_header(path: &FsPath, header: &str) -> Result<MmHeader> {
    let err = |msg: String| Err(io_err(path, Some(1), msg));
    let h: Vec<String> = header
        .split_whitespace()
        .map(|s| s.to_ascii_lowercase())
        .collect();
    if h.first().map(String::as_str) != Some("%%matrixmarket") {
        return err(format!("bad header: expected \"{MM_HEADER}\""));
    }
    if h.len() != 5 {
        return err(format!(
            "bad header \"{}\": expected \"{MM_HEADER}\"",
            excerpt(header.trim())
        ));
    }
    if h[1] != "matrix" {
        return err(format!(
            "unsupported object \"{}\" (expected matrix: \"{MM_HEADER}\")",
            excerpt(&h[1])
        ));
    }
    let array = match h[2].as_str() {
        "coordinate" => false,
        "array" => true,
        other => {
            return err(format!(
                "unsupported format \"{}\" (expected coordinate or array)",
                excerpt(other)
            ));
        }
    };
    let integer = match h[3].as_str() {
        "real" => false,
        "integer" => true,
        "pattern" => {
            return err(
                "field \"pattern\" is not supported: a pattern file stores no values (write the matrix with field real or integer)".into(),
            );
        }
        "complex" => {
            return err(
                "field \"complex\" is not supported: A, N and T are real matrices (use field real or integer)".into(),
            );
        }
        other => {
            return err(format!(
                "unsupported field \"{}\" (expected real or integer)",
                excerpt(other)
            ));
        }
    };
    let symmetric = match h[4].as_str() {
        "general" => false,
        "symmetric" => true,
        "hermitian" => {
            return err(
                "symmetry \"hermitian\" is not supported: it needs complex values (use general or symmetric)".into(),
            );
        }
        "skew-symmetric" => {
            return err(
                "symmetry \"skew-symmetric\" is not supported: no stiffness or contact matrix is skew-symmetric (use general or symmetric)".into(),
            );
        }
        other => {
            return err(format!(
                "unsupported symmetry \"{}\" (expected general or symmetric)",
                excerpt(other)
            ));
        }
    };
    Ok(MmHeader {
        array,
        integer,
        symmetric,
    })
}

fn parse_mtx(
    path: &FsPath,
    text: &str,
    expect: Option<(usize, usize)>,
    expect_what: &str,
) -> Result<CsrMatrix> {
    let mut lines = text.lines().enumerate().map(|(i, l)| (i + 1, l));
    // Header.
    let Some((_, header)) = lines.next() else {
        return Err(io_err(
            path,
            Some(1),
            "empty file (expected a %%MatrixMarket header)",
        ));
    };
    let hd = parse_mm_header(path, header)?;
    let symmetric = hd.symmetric;
    let value = |ln: usize, tok: &str| {
        if hd.integer {
            parse_integer(path, ln, tok)
        } else {
            parse_real(path, ln, tok, "value")
        }
    };
    // Size line (after comments and blank lines).
    let mut size = None;
    for (ln, l) in lines.by_ref() {
        let t = l.trim();
        if t.is_empty() || t.starts_with('%') {
            continue;
        }
        size = Some((ln, t));
        break;
    }
    let size_form = if hd.array {
        "rows cols"
    } else {
        "rows cols entries"
    };
    let Some((size_ln, size_line)) = size else {
        return Err(io_err(
            path,
            None,
            format!("missing size line \"{size_form}\" after the header"),
        ));
    };
    let toks: Vec<&str> = size_line.split_whitespace().take(4).collect();
    if toks.len() != if hd.array { 2 } else { 3 } {
        return Err(io_err(
            path,
            Some(size_ln),
            format!(
                "bad size line \"{}\": expected \"{size_form}\"",
                excerpt(size_line)
            ),
        ));
    }
    let nrows = parse_count(path, size_ln, toks[0], "row count")?;
    let ncols = parse_count(path, size_ln, toks[1], "column count")?;
    if let Some((er, ec)) = expect
        && (er, ec) != (nrows, ncols)
    {
        return Err(io_err(
            path,
            Some(size_ln),
            format!("matrix is {nrows}x{ncols}, expected {er}x{ec} ({expect_what})"),
        ));
    }
    if symmetric && nrows != ncols {
        return Err(io_err(
            path,
            Some(size_ln),
            format!("a symmetric matrix must be square, this one is {nrows}x{ncols}"),
        ));
    }
    let name = path.file_name().map_or_else(
        || path.display().to_string(),
        |s| s.to_string_lossy().into_owned(),
    );
    if hd.array {
        let triplets = parse_array_values(path, lines, nrows, ncols, symmetric, size_ln, value)?;
        return CsrMatrix::from_triplets(&name, nrows, ncols, &triplets)
            .map_err(|e| io_err(path, None, e));
    }
    let nnz = parse_count(path, size_ln, toks[2], "entry count")?;
    // Reserve for the announced entries, but never more than the file can hold (an entry
    // line has at least 6 bytes): a corrupt size line must not trigger a huge allocation.
    let max_entries = nnz.min(text.len() / 6 + 1);
    let cap = if symmetric {
        2 * max_entries
    } else {
        max_entries
    };
    let mut triplets: Vec<(usize, usize, f64)> = Vec::with_capacity(cap);
    // For symmetric files: which triangle the off-diagonal entries are in, and where seen.
    let mut triangle: Option<(bool, usize)> = None;
    let mut count = 0usize;
    let mut last_ln = size_ln;
    for (ln, l) in lines {
        last_ln = ln;
        let t = l.trim();
        if t.is_empty() || t.starts_with('%') {
            continue;
        }
        count += 1;
        if count > nnz {
            return Err(io_err(
                path,
                Some(ln),
                format!("more entries than the {nnz} announced on line {size_ln}"),
            ));
        }
        let mut it = t.split_ascii_whitespace();
        let (Some(ti), Some(tj), Some(tv), None) = (it.next(), it.next(), it.next(), it.next())
        else {
            return Err(io_err(
                path,
                Some(ln),
                format!(
                    "expected \"row col value\", found {} fields",
                    t.split_ascii_whitespace().count()
                ),
            ));
        };
        let i = parse_count(path, ln, ti, "row index")?;
        let j = parse_count(path, ln, tj, "column index")?;
        if i == 0 || i > nrows {
            return Err(io_err(
                path,
                Some(ln),
                format!("row index {i} out of range 1..={nrows} (indices are 1-based)"),
            ));
        }
        if j == 0 || j > ncols {
            return Err(io_err(
                path,
                Some(ln),
                format!("column index {j} out of range 1..={ncols} (indices are 1-based)"),
            ));
        }
        let v = value(ln, tv)?;
        triplets.push((i - 1, j - 1, v));
        if symmetric && i != j {
            let lower = i > j;
            match triangle {
                None => triangle = Some((lower, ln)),
                Some((tl, first)) if tl != lower => {
                    return Err(io_err(
                        path,
                        Some(ln),
                        format!(
                            "symmetric file stores entries in both triangles (entry ({i}, {j}) is in the {} triangle, line {first} was in the {} one); store one triangle only",
                            if lower { "lower" } else { "upper" },
                            if tl { "lower" } else { "upper" }
                        ),
                    ));
                }
                _ => {}
            }
            triplets.push((j - 1, i - 1, v));
        }
    }
    if count < nnz {
        return Err(io_err(
            path,
            Some(last_ln),
            format!("only {count} entries, {nnz} announced on line {size_ln}"),
        ));
    }
    if nrows > count {
        // Some row is empty: no stiffness or contact matrix may have one (A would be
        // singular, B = [N; T] rank-deficient). Checked here so that a corrupt size line
        // cannot make the CSR conversion allocate for rows that do not exist.
        return Err(io_err(
            path,
            Some(size_ln),
            format!(
                "{nrows} rows but only {count} entries: some row is empty (A would be singular, B = [N; T] rank-deficient)"
            ),
        ));
    }
    CsrMatrix::from_triplets(&name, nrows, ncols, &triplets).map_err(|e| io_err(path, None, e))
}

/// The values of an `array` file (dense, column-major, one value a line; for `symmetric`
/// the lower triangle with the diagonal, column by column, as the Matrix Market standard
/// says) as 0-based triplets, both triangles for `symmetric`, exact zeros left out.
fn parse_array_values<'a>(
    path: &FsPath,
    lines: impl Iterator<Item = (usize, &'a str)>,
    nrows: usize,
    ncols: usize,
    symmetric: bool,
    size_ln: usize,
    value: impl Fn(usize, &str) -> Result<f64>,
) -> Result<Vec<(usize, usize, f64)>> {
    let expected = if symmetric {
        nrows.checked_mul(nrows + 1).map(|m| m / 2)
    } else {
        nrows.checked_mul(ncols)
    }
    .ok_or_else(|| {
        io_err(
            path,
            Some(size_ln),
            format!("a {nrows}x{ncols} array is too large"),
        )
    })?;
    let what = if symmetric {
        format!(
            "{expected} values (the lower triangle of a {nrows}x{ncols} array, column by column)"
        )
    } else {
        format!("{expected} values (a {nrows}x{ncols} array, column by column)")
    };
    let mut triplets: Vec<(usize, usize, f64)> = Vec::new();
    // Position of the next value: column j, row i.
    let (mut i, mut j) = (0usize, 0usize);
    let mut count = 0usize;
    let mut last_ln = size_ln;
    for (ln, l) in lines {
        last_ln = ln;
        let t = l.trim();
        if t.is_empty() || t.starts_with('%') {
            continue;
        }
        if count == expected {
            return Err(io_err(
                path,
                Some(ln),
                format!("more values than the {what} announced on line {size_ln}"),
            ));
        }
        let mut it = t.split_ascii_whitespace();
        let (Some(tv), None) = (it.next(), it.next()) else {
            return Err(io_err(
                path,
                Some(ln),
                format!(
                    "expected one value per line (array format), found {} fields",
                    t.split_ascii_whitespace().count()
                ),
            ));
        };
        let v = value(ln, tv)?;
        if v != 0.0 {
            triplets.push((i, j, v));
            if symmetric && i != j {
                triplets.push((j, i, v));
            }
        }
        count += 1;
        i += 1;
        if i == nrows {
            j += 1;
            i = if symmetric { j } else { 0 };
        }
    }
    if count < expected {
        return Err(io_err(
            path,
            Some(last_ln),
            format!("only {count} values, expected {what} as announced on line {size_ln}"),
        ));
    }
    Ok(triplets)
}

/// Reads `expect` numbers, one a line (blank lines ignored).
fn read_vector(path: &FsPath, expect: usize, expect_name: &str) -> Result<Vec<f64>> {
    let (path, text) = read_text(path)?;
    parse_vector(&path, &text, expect, expect_name)
}

fn parse_vector(path: &FsPath, text: &str, expect: usize, expect_name: &str) -> Result<Vec<f64>> {
    // A number takes at least 2 bytes with its newline: never reserve more than that.
    let mut v = Vec::with_capacity(expect.min(text.len() / 2 + 1));
    for (i, l) in text.lines().enumerate() {
        let ln = i + 1;
        let t = l.trim();
        if t.is_empty() {
            continue;
        }
        let mut toks = t.split_whitespace();
        let tok = toks.next().unwrap_or_default();
        if toks.next().is_some() {
            return Err(io_err(path, Some(ln), "expected one number per line"));
        }
        if v.len() == expect {
            return Err(io_err(
                path,
                Some(ln),
                format!("more than {expect_name} = {expect} numbers (from meta.json)"),
            ));
        }
        v.push(parse_real(path, ln, tok, "value")?);
    }
    if v.len() != expect {
        return Err(io_err(
            path,
            None,
            format!(
                "{} numbers, expected {expect_name} = {expect} (from meta.json)",
                v.len()
            ),
        ));
    }
    Ok(v)
}

fn mtx_text(m: &CsrMatrix) -> String {
    let mut s = String::with_capacity(32 * m.nnz() + 64);
    s.push_str("%%MatrixMarket matrix coordinate real general\n");
    s.push_str("% written by fricont\n");
    let _ = writeln!(s, "{} {} {}", m.nrows(), m.ncols(), m.nnz());
    for i in 0..m.nrows() {
        for (j, v) in m.row(i) {
            let _ = writeln!(s, "{} {} {:e}", i + 1, j + 1, v);
        }
    }
    s
}

fn vector_text(v: &[f64]) -> String {
    let mut s = String::with_capacity(24 * v.len());
    for x in v {
        let _ = writeln!(s, "{x:e}");
    }
    s
}

#[cfg(test)]
mod tests {

    /// A problem directory with every file gzip-compressed reads as the plain one; a
    /// corrupt entry in a compressed file is reported with the .gz name and its line.
    #[test]
    fn gzip_files_are_read() {
        use std::io::Write as _;
        let dir = std::env::temp_dir().join(format!("fricont-gz-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let case = crate::generator::generate(&crate::generator::RectSpec {
            nx: 5,
            ny: 3,
            gap: 0.01,
            ..crate::generator::RectSpec::press_shear()
        })
        .unwrap();
        case.write_dir(&dir).unwrap();
        for name in [
            "A.mtx",
            "N.mtx",
            "T.mtx",
            "f0.txt",
            "f1.txt",
            "gap.txt",
            "meta.json",
        ] {
            let plain = dir.join(name);
            let bytes = std::fs::read(&plain).unwrap();
            let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
            enc.write_all(&bytes).unwrap();
            std::fs::write(dir.join(format!("{name}.gz")), enc.finish().unwrap()).unwrap();
            std::fs::remove_file(&plain).unwrap();
        }
        let back = CaseData::read_dir(&dir).unwrap();
        assert_eq!(back, case);
        // corrupt line 5 of A.mtx.gz
        let text = {
            use std::io::Read as _;
            let mut s = String::new();
            flate2::read::GzDecoder::new(std::fs::File::open(dir.join("A.mtx.gz")).unwrap())
                .read_to_string(&mut s)
                .unwrap();
            s
        };
        let mut lines: Vec<&str> = text.lines().collect();
        let bad = lines.iter().position(|l| !l.starts_with('%')).unwrap() + 2;
        lines[bad] = "1 1 abc";
        let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
        enc.write_all(lines.join("\n").as_bytes()).unwrap();
        std::fs::write(dir.join("A.mtx.gz"), enc.finish().unwrap()).unwrap();
        let err = CaseData::read_dir(&dir).unwrap_err().to_string();
        assert!(
            err.contains(&format!("A.mtx.gz:{}:", bad + 1)) && err.contains("abc"),
            "{err}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
    use super::*;
    use std::path::PathBuf;

    /// A fresh empty directory under the system temp dir, removed on drop.
    struct TempDir(PathBuf);
    impl TempDir {
        fn new(tag: &str) -> Self {
            use std::sync::atomic::{AtomicUsize, Ordering};
            static K: AtomicUsize = AtomicUsize::new(0);
            let d = std::env::temp_dir().join(format!(
                "fricont-io-{tag}-{}-{}",
                std::process::id(),
                K.fetch_add(1, Ordering::Relaxed)
            ));
            let _ = std::fs::remove_dir_all(&d);
            std::fs::create_dir_all(&d).unwrap();
            TempDir(d)
        }
    }
    impl Drop for TempDir {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    // A 3-dof, 1-node problem written by hand:
    // A = [[4,-1,0],[-1,4,-1],[0,-1,4]] (symmetric, lower triangle stored), N = [0 1 0],
    // T = [0 0 1].
    const A_SYM: &str = "%%MatrixMarket matrix coordinate real symmetric\n% a comment\n\n3 3 5\n1 1 4\n2 1 -1\n2 2 4.0\n3 2 -1e0\n3 3 4\n";
    const N_MTX: &str = "%%MatrixMarket matrix coordinate real general\n1 3 1\n1 2 1\n";
    const T_MTX: &str = "%%MatrixMarket matrix coordinate real general\n1 3 1\n1 3 1\n";
    const META: &str =
        r#"{"n": 3, "p": 1, "F": 0.5, "alpha_start": -1, "alpha_end": 2.5, "mesh": "hand-made"}"#;

    fn write_case(d: &FsPath) {
        std::fs::write(d.join("A.mtx"), A_SYM).unwrap();
        std::fs::write(d.join("N.mtx"), N_MTX).unwrap();
        std::fs::write(d.join("T.mtx"), T_MTX).unwrap();
        std::fs::write(d.join("f0.txt"), "0\n-1.5\n0\n").unwrap();
        std::fs::write(d.join("f1.txt"), "0\n0\n1.0D+00\n").unwrap();
        std::fs::write(d.join("meta.json"), META).unwrap();
    }

    fn dense(m: &CsrMatrix) -> Vec<f64> {
        let mut d = vec![0.0; m.nrows() * m.ncols()];
        for i in 0..m.nrows() {
            for (j, v) in m.row(i) {
                d[i * m.ncols() + j] = v;
            }
        }
        d
    }

    #[test]
    fn reads_hand_written_case_and_expands_symmetric() {
        let t = TempDir::new("read");
        write_case(&t.0);
        let c = CaseData::read_dir(&t.0).unwrap();
        assert_eq!(
            dense(&c.a),
            vec![4.0, -1.0, 0.0, -1.0, 4.0, -1.0, 0.0, -1.0, 4.0]
        );
        assert_eq!(dense(&c.n_mat), vec![0.0, 1.0, 0.0]);
        assert_eq!(dense(&c.t_mat), vec![0.0, 0.0, 1.0]);
        assert_eq!(c.f0, vec![0.0, -1.5, 0.0]);
        assert_eq!(c.f1, vec![0.0, 0.0, 1.0]);
        assert_eq!(c.gap, None);
        assert_eq!(c.friction, vec![0.5]);
        assert_eq!((c.alpha_start, c.alpha_end), (-1.0, 2.5));
        assert_eq!(c.meta["mesh"], "hand-made");
        assert_eq!((c.n(), c.p()), (3, 1));
    }

    #[test]
    fn upper_triangle_symmetric_is_accepted() {
        let t = TempDir::new("upper");
        write_case(&t.0);
        std::fs::write(
            t.0.join("A.mtx"),
            "%%MatrixMarket matrix coordinate real symmetric\n3 3 5\n1 1 4\n1 2 -1\n2 2 4\n2 3 -1\n3 3 4\n",
        )
        .unwrap();
        let c = CaseData::read_dir(&t.0).unwrap();
        assert_eq!(
            dense(&c.a),
            vec![4.0, -1.0, 0.0, -1.0, 4.0, -1.0, 0.0, -1.0, 4.0]
        );
    }

    #[test]
    fn round_trip_is_exact() {
        let t = TempDir::new("rt");
        // Values that do not print exactly in short decimal form.
        let a = CsrMatrix::from_dense(
            3,
            3,
            &[
                1.0 / 3.0,
                -0.1,
                0.0,
                -0.1,
                std::f64::consts::PI,
                1e-300,
                0.0,
                1e-300,
                7.0e12,
            ],
        )
        .unwrap();
        let n = CsrMatrix::from_dense(2, 3, &[1.0, 0.0, 0.0, 0.0, 0.0, -1.0]).unwrap();
        let tm = CsrMatrix::from_dense(2, 3, &[0.0, 1.0, 0.0, 0.2, 0.0, 0.0]).unwrap();
        let mut meta = serde_json::Map::new();
        meta.insert("title".into(), "round trip".into());
        meta.insert("nested".into(), serde_json::json!({"k": [1, 2]}));
        let c = CaseData {
            a,
            n_mat: n,
            t_mat: tm,
            f0: vec![0.1, -2.0 / 3.0, 5e-324],
            f1: vec![1.0, f64::MAX, -0.0],
            gap: Some(vec![1e-3, 0.0]),
            friction: vec![0.3, 2.9999999999999996],
            alpha_start: 0.1 + 0.2,
            // Read back one ulp off by serde_json without `float_roundtrip`.
            alpha_end: -f64::from_bits(4595965843552456931),
            meta: serde_json::Value::Object(meta),
        };
        c.write_dir(&t.0).unwrap();
        let back = CaseData::read_dir(&t.0).unwrap();
        assert_eq!(back.a, c.a);
        assert_eq!(back.n_mat, c.n_mat);
        assert_eq!(back.t_mat, c.t_mat);
        assert_eq!(back.f0, c.f0);
        assert_eq!(back.f1, c.f1);
        assert_eq!(back.gap, c.gap);
        assert_eq!(back.friction, c.friction);
        assert_eq!(back.alpha_start, c.alpha_start);
        assert_eq!(back.alpha_end, c.alpha_end);
        assert_eq!(back.meta["title"], "round trip");
        assert_eq!(back.meta["nested"]["k"][1], 2);
        assert_eq!(back.meta["n"], 3);
        assert_eq!(back.meta["p"], 2);
        // Written again without a gap: gap.txt disappears.
        let mut c2 = back.clone();
        c2.gap = None;
        c2.write_dir(&t.0).unwrap();
        assert!(!t.0.join("gap.txt").exists());
        assert_eq!(CaseData::read_dir(&t.0).unwrap().gap, None);
    }

    #[test]
    fn write_rejects_inconsistent_fields() {
        let t = TempDir::new("wbad");
        write_case(&t.0);
        let mut c = CaseData::read_dir(&t.0).unwrap();
        c.f0.pop();
        let e = c.write_dir(&t.0.join("out")).unwrap_err();
        assert!(
            matches!(e, Error::Core(fricont::Error::Dimension(_))),
            "{e}"
        );
    }

    /// Writes the hand case, replaces one file, reads, and returns the error message.
    fn broken(file: &str, content: &str) -> String {
        let t = TempDir::new("bad");
        write_case(&t.0);
        std::fs::write(t.0.join(file), content).unwrap();
        let e = CaseData::read_dir(&t.0).unwrap_err();
        assert!(matches!(e, Error::Io(_)), "{e:?}");
        let msg = e.to_string();
        assert!(!msg.contains('\n'), "message is not one line: {msg}");
        assert!(msg.contains(file), "message does not name {file}: {msg}");
        msg
    }

    #[test]
    fn error_bad_header() {
        let m = broken(
            "N.mtx",
            "%MatrixMarket matrix coordinate real general\n1 3 1\n1 2 1\n",
        );
        assert!(m.contains(":1:") && m.contains("bad header"), "{m}");
        let m = broken(
            "N.mtx",
            "%%MatrixMarket matrix coordinate complex general\n1 3 1\n1 2 1 0\n",
        );
        assert!(
            m.contains(":1:") && m.contains("\"complex\" is not supported"),
            "{m}"
        );
        let m = broken(
            "N.mtx",
            "%%MatrixMarket matrix coordinate pattern general\n1 3 1\n1 2\n",
        );
        assert!(
            m.contains(":1:") && m.contains("\"pattern\" is not supported"),
            "{m}"
        );
        assert!(m.contains("no values"), "{m}");
        let m = broken(
            "A.mtx",
            "%%MatrixMarket matrix coordinate complex hermitian\n3 3 1\n1 1 4 0\n",
        );
        assert!(m.contains(":1:") && m.contains("complex"), "{m}");
        let m = broken(
            "A.mtx",
            "%%MatrixMarket matrix array real hermitian\n3 3\n4\n0\n0\n4\n0\n4\n",
        );
        assert!(
            m.contains(":1:") && m.contains("\"hermitian\" is not supported"),
            "{m}"
        );
        let m = broken(
            "N.mtx",
            "%%MatrixMarket matrix coordinate real skew-symmetric\n1 3 1\n1 2 1\n",
        );
        assert!(m.contains("\"skew-symmetric\" is not supported"), "{m}");
        let m = broken(
            "N.mtx",
            "%%MatrixMarket vector coordinate real general\n1 3 1\n1 2 1\n",
        );
        assert!(m.contains("object \"vector\""), "{m}");
        let m = broken(
            "N.mtx",
            "%%MatrixMarket matrix sparse real general\n1 3 1\n1 2 1\n",
        );
        assert!(m.contains("format \"sparse\""), "{m}");
        let m = broken("N.mtx", "");
        assert!(m.contains("empty"), "{m}");
    }

    /// `integer` files (coordinate and array) read as the real ones; a non-integer value
    /// in an integer file is an error naming the line.
    #[test]
    fn integer_fields_are_read() {
        let t = TempDir::new("int");
        write_case(&t.0);
        std::fs::write(
            t.0.join("A.mtx"),
            "%%MatrixMarket matrix coordinate integer symmetric\n3 3 5\n1 1 4\n2 1 -1\n2 2 +4\n3 2 -1\n3 3 4\n",
        )
        .unwrap();
        std::fs::write(
            t.0.join("N.mtx"),
            "%%MatrixMarket matrix array integer general\n1 3\n0\n1\n0\n",
        )
        .unwrap();
        let c = CaseData::read_dir(&t.0).unwrap();
        assert_eq!(
            dense(&c.a),
            vec![4.0, -1.0, 0.0, -1.0, 4.0, -1.0, 0.0, -1.0, 4.0]
        );
        assert_eq!(dense(&c.n_mat), vec![0.0, 1.0, 0.0]);
        assert_eq!(c.n_mat.nnz(), 1, "exact zeros of an array are not stored");
        let m = broken(
            "T.mtx",
            "%%MatrixMarket matrix coordinate integer general\n1 3 1\n1 3 1.5\n",
        );
        assert!(
            m.contains(":3:") && m.contains("\"1.5\" is not an integer"),
            "{m}"
        );
        let m = broken(
            "T.mtx",
            "%%MatrixMarket matrix array integer general\n1 3\n0\n0\n1e0\n",
        );
        assert!(
            m.contains(":5:") && m.contains("\"1e0\" is not an integer"),
            "{m}"
        );
    }

    /// `array` files are dense and column-major (the Matrix Market standard): a 2 × 3
    /// general array and a 3 × 3 symmetric one (lower triangle, column by column).
    #[test]
    fn array_files_are_column_major() {
        let p = FsPath::new("M.mtx");
        let m = parse_mtx(
            p,
            "%%MatrixMarket matrix array real general\n% a comment\n2 3\n1\n2\n3\n\n4\n5\n6.5\n",
            None,
            "",
        )
        .unwrap();
        assert_eq!((m.nrows(), m.ncols()), (2, 3));
        assert_eq!(dense(&m), vec![1.0, 3.0, 5.0, 2.0, 4.0, 6.5]);
        // lower triangle by columns: (1,1) (2,1) (3,1) | (2,2) (3,2) | (3,3)
        let m = parse_mtx(
            p,
            "%%MatrixMarket matrix array real symmetric\n3 3\n4\n-1\n0\n5\n-2\n6\n",
            None,
            "",
        )
        .unwrap();
        assert_eq!(
            dense(&m),
            vec![4.0, -1.0, 0.0, -1.0, 5.0, -2.0, 0.0, -2.0, 6.0]
        );
        assert_eq!(m.nnz(), 7);
        // and through a problem directory, with the sizes checked against meta.json
        let t = TempDir::new("array");
        write_case(&t.0);
        std::fs::write(
            t.0.join("A.mtx"),
            "%%MatrixMarket matrix array real symmetric\n3 3\n4\n-1\n0\n4\n-1\n4\n",
        )
        .unwrap();
        std::fs::write(
            t.0.join("T.mtx"),
            "%%MatrixMarket matrix array real general\n1 3\n0\n0\n1.0D+00\n",
        )
        .unwrap();
        let c = CaseData::read_dir(&t.0).unwrap();
        assert_eq!(
            dense(&c.a),
            vec![4.0, -1.0, 0.0, -1.0, 4.0, -1.0, 0.0, -1.0, 4.0]
        );
        assert_eq!(dense(&c.t_mat), vec![0.0, 0.0, 1.0]);
    }

    #[test]
    fn array_file_errors() {
        let m = broken(
            "N.mtx",
            "%%MatrixMarket matrix array real general\n1 3\n0\n1\n",
        );
        assert!(
            m.contains(":4:") && m.contains("only 2 values, expected 3"),
            "{m}"
        );
        let m = broken(
            "N.mtx",
            "%%MatrixMarket matrix array real general\n1 3\n0\n1\n0\n2\n",
        );
        assert!(m.contains(":6:") && m.contains("more values"), "{m}");
        let m = broken(
            "N.mtx",
            "%%MatrixMarket matrix array real general\n1 3\n0 1\n0\n",
        );
        assert!(m.contains(":3:") && m.contains("one value per line"), "{m}");
        let m = broken(
            "N.mtx",
            "%%MatrixMarket matrix array real general\n1 3 3\n0\n1\n0\n",
        );
        assert!(m.contains(":2:") && m.contains("\"rows cols\""), "{m}");
        let m = broken(
            "N.mtx",
            "%%MatrixMarket matrix array real symmetric\n1 3\n0\n1\n0\n",
        );
        assert!(m.contains("must be square"), "{m}");
        let m = broken(
            "A.mtx",
            "%%MatrixMarket matrix array real symmetric\n3 3\n4\n-1\n0\n4\nNaN\n4\n",
        );
        assert!(m.contains(":7:") && m.contains("NaN"), "{m}");
        let m = broken("A.mtx", "%%MatrixMarket matrix array real general\n3 3\n");
        assert!(m.contains("only 0 values, expected 9"), "{m}");
    }

    /// Repeated entries of a coordinate file are summed (assembly), also in a symmetric
    /// file's triangle; the symmetry check of a general A sees the sums.
    #[test]
    fn coordinate_duplicates_are_summed() {
        let t = TempDir::new("dup");
        write_case(&t.0);
        // A(2,1) = -0.25 - 0.75, A(3,3) = 1 + 3: the hand case's A
        std::fs::write(
            t.0.join("A.mtx"),
            "%%MatrixMarket matrix coordinate real symmetric\n3 3 7\n1 1 4\n2 1 -0.25\n2 2 4\n3 3 1\n3 2 -1\n2 1 -0.75\n3 3 3\n",
        )
        .unwrap();
        let c = CaseData::read_dir(&t.0).unwrap();
        assert_eq!(
            dense(&c.a),
            vec![4.0, -1.0, 0.0, -1.0, 4.0, -1.0, 0.0, -1.0, 4.0]
        );
        // general: A(1,2) given as 2 × -0.5, A(2,1) as -1
        std::fs::write(
            t.0.join("A.mtx"),
            "%%MatrixMarket matrix coordinate real general\n3 3 8\n1 1 4\n1 2 -0.5\n1 2 -0.5\n2 1 -1\n2 2 4\n2 3 -1\n3 2 -1\n3 3 4\n",
        )
        .unwrap();
        let c = CaseData::read_dir(&t.0).unwrap();
        assert_eq!(
            dense(&c.a),
            vec![4.0, -1.0, 0.0, -1.0, 4.0, -1.0, 0.0, -1.0, 4.0]
        );
        assert!(c.problem(None).is_ok());
    }

    /// A line of a megabyte, anywhere, gives a one-line message quoting only a short
    /// excerpt of it (with its length).
    #[test]
    fn long_lines_are_not_echoed() {
        let big = "x".repeat(1 << 20);
        let digits = "7".repeat(1 << 20);
        let cases: Vec<(&str, String)> = vec![
            (
                "N.mtx",
                format!("%%MatrixMarket matrix coordinate {big} general\n1 3 1\n1 2 1\n"),
            ),
            (
                "N.mtx",
                format!("%%MatrixMarket matrix {big} real general\n1 3 1\n1 2 1\n"),
            ),
            (
                "N.mtx",
                format!("%%MatrixMarket matrix coordinate real general {big}\n1 3 1\n1 2 1\n"),
            ),
            (
                "N.mtx",
                format!("%%MatrixMarket matrix coordinate real general\n1 3 {big}\n1 2 1\n"),
            ),
            (
                "N.mtx",
                format!("%%MatrixMarket matrix coordinate real general\n1 3 1 {big}\n1 2 1\n"),
            ),
            (
                "N.mtx",
                format!("%%MatrixMarket matrix coordinate real general\n1 3 1\n1 {digits} 1\n"),
            ),
            (
                "N.mtx",
                format!("%%MatrixMarket matrix coordinate real general\n1 3 1\n1 2 {big}\n"),
            ),
            (
                "N.mtx",
                format!("%%MatrixMarket matrix coordinate integer general\n1 3 1\n1 2 {digits}\n"),
            ),
            (
                "N.mtx",
                format!("%%MatrixMarket matrix array real general\n1 3\n0\n{big}\n0\n"),
            ),
            ("f0.txt", format!("0\n{big}\n0\n")),
            (
                "meta.json",
                format!(
                    "{{\"n\": \"{big}\", \"p\": 1, \"F\": 0.5, \"alpha_start\": 0, \"alpha_end\": 1}}"
                ),
            ),
            (
                "meta.json",
                format!(
                    "{{\"n\": 3, \"p\": 1, \"F\": [\"{big}\"], \"alpha_start\": 0, \"alpha_end\": 1}}"
                ),
            ),
        ];
        for (file, content) in cases {
            let m = broken(file, &content);
            assert!(
                m.len() < 400,
                "{file}: a {} byte message: {}…",
                m.len(),
                &m[..200]
            );
        }
        // the excerpt says how long the text was
        let m = broken("f0.txt", &format!("0\n{big}\n0\n"));
        assert!(m.contains(":2:") && m.contains("(1048576 bytes)"), "{m}");
        assert_eq!(excerpt("short"), "short");
        assert_eq!(
            excerpt(&"é".repeat(50)),
            format!("{}… (100 bytes)", "é".repeat(32))
        );
    }

    #[test]
    fn error_bad_size_line() {
        let m = broken(
            "N.mtx",
            "%%MatrixMarket matrix coordinate real general\n% c\n1 3\n1 2 1\n",
        );
        assert!(m.contains(":3:") && m.contains("size line"), "{m}");
        let m = broken(
            "N.mtx",
            "%%MatrixMarket matrix coordinate real general\n1 x 1\n1 2 1\n",
        );
        assert!(m.contains(":2:") && m.contains("\"x\""), "{m}");
        let m = broken(
            "N.mtx",
            "%%MatrixMarket matrix coordinate real general\n% only comments\n",
        );
        assert!(m.contains("missing size line"), "{m}");
    }

    #[test]
    fn error_wrong_counts() {
        // Fewer entries than announced.
        let m = broken(
            "A.mtx",
            "%%MatrixMarket matrix coordinate real symmetric\n3 3 5\n1 1 4\n2 2 4\n3 3 4\n",
        );
        assert!(m.contains("only 3 entries, 5 announced"), "{m}");
        // More entries than announced.
        let m = broken(
            "T.mtx",
            "%%MatrixMarket matrix coordinate real general\n1 3 1\n1 3 1\n1 1 2\n",
        );
        assert!(m.contains(":4:") && m.contains("more entries"), "{m}");
        // Vector too short / too long.
        let m = broken("f0.txt", "1\n2\n");
        assert!(m.contains("2 numbers, expected n = 3"), "{m}");
        let m = broken("f1.txt", "1\n2\n3\n4\n");
        assert!(m.contains(":4:") && m.contains("more than n = 3"), "{m}");
        let m = broken("f1.txt", "1 2\n2\n3\n");
        assert!(m.contains(":1:") && m.contains("one number"), "{m}");
        // Entry line with a missing field.
        let m = broken(
            "N.mtx",
            "%%MatrixMarket matrix coordinate real general\n1 3 1\n1 2\n",
        );
        assert!(m.contains(":3:") && m.contains("fields"), "{m}");
    }

    #[test]
    fn error_index_out_of_range() {
        let m = broken(
            "N.mtx",
            "%%MatrixMarket matrix coordinate real general\n1 3 1\n1 4 1\n",
        );
        assert!(
            m.contains(":3:") && m.contains("column index 4 out of range"),
            "{m}"
        );
        let m = broken(
            "N.mtx",
            "%%MatrixMarket matrix coordinate real general\n1 3 1\n0 2 1\n",
        );
        assert!(m.contains(":3:") && m.contains("row index 0"), "{m}");
        let m = broken(
            "N.mtx",
            "%%MatrixMarket matrix coordinate real general\n1 3 1\n-1 2 1\n",
        );
        assert!(m.contains(":3:") && m.contains("\"-1\""), "{m}");
    }

    #[test]
    fn error_non_numeric_and_nan() {
        let m = broken(
            "A.mtx",
            "%%MatrixMarket matrix coordinate real symmetric\n3 3 1\n1 1 four\n",
        );
        assert!(
            m.contains(":3:") && m.contains("\"four\" is not a number"),
            "{m}"
        );
        let m = broken(
            "A.mtx",
            "%%MatrixMarket matrix coordinate real symmetric\n3 3 1\n1 1 NaN\n",
        );
        assert!(m.contains(":3:") && m.contains("NaN"), "{m}");
        let m = broken("f0.txt", "0\ninf\n0\n");
        assert!(m.contains(":2:") && m.contains("inf"), "{m}");
        let m = broken("f0.txt", "0\n1,5\n0\n");
        assert!(m.contains(":2:") && m.contains("\"1,5\""), "{m}");
        let m = broken("gap.txt", "nan\n");
        assert!(m.contains(":1:") && m.contains("NaN"), "{m}");
    }

    #[test]
    fn error_symmetric_both_triangles_or_not_square() {
        let m = broken(
            "A.mtx",
            "%%MatrixMarket matrix coordinate real symmetric\n3 3 3\n2 1 -1\n1 1 4\n1 2 -1\n",
        );
        assert!(m.contains(":5:") && m.contains("both triangles"), "{m}");
        let m = broken(
            "N.mtx",
            "%%MatrixMarket matrix coordinate real symmetric\n1 3 1\n1 1 1\n",
        );
        assert!(m.contains("must be square"), "{m}");
    }

    #[test]
    fn error_dimensions_disagree_with_meta() {
        let m = broken(
            "N.mtx",
            "%%MatrixMarket matrix coordinate real general\n2 3 1\n1 2 1\n",
        );
        assert!(m.contains("2x3, expected 1x3"), "{m}");
        let m = broken(
            "A.mtx",
            "%%MatrixMarket matrix coordinate real general\n4 4 1\n1 1 1\n",
        );
        assert!(m.contains("4x4, expected 3x3"), "{m}");
        let m = broken("gap.txt", "0\n0\n");
        assert!(m.contains("more than p = 1"), "{m}");
    }

    #[test]
    fn error_meta() {
        let m = broken(
            "meta.json",
            r#"{"n": 3, "p": 1, "F": 0.5, "alpha_start": -1}"#,
        );
        assert!(m.contains("\"alpha_end\""), "{m}");
        let m = broken(
            "meta.json",
            r#"{"n": 3.5, "p": 1, "F": 0.5, "alpha_start": -1, "alpha_end": 1}"#,
        );
        assert!(m.contains("\"n\" must be a positive integer"), "{m}");
        let m = broken(
            "meta.json",
            r#"{"n": 3, "p": 0, "F": 0.5, "alpha_start": -1, "alpha_end": 1}"#,
        );
        assert!(m.contains("\"p\" must be a positive integer"), "{m}");
        let m = broken(
            "meta.json",
            r#"{"n": 3, "p": 1, "F": [0.5, 1], "alpha_start": -1, "alpha_end": 1}"#,
        );
        assert!(m.contains("\"F\" has 2 values"), "{m}");
        let m = broken(
            "meta.json",
            r#"{"n": 3, "p": 1, "F": -0.5, "alpha_start": -1, "alpha_end": 1}"#,
        );
        assert!(m.contains(">= 0"), "{m}");
        let m = broken(
            "meta.json",
            r#"{"n": 3, "p": 1, "F": "high", "alpha_start": -1, "alpha_end": 1}"#,
        );
        assert!(m.contains("\"F\" must be a finite number"), "{m}");
        let m = broken("meta.json", "{\"n\": 3,\n \"p\": 1,,\n}");
        assert!(m.contains(":2:") && m.contains("invalid JSON"), "{m}");
        let m = broken("meta.json", "[1, 2]");
        assert!(m.contains("object"), "{m}");
    }

    #[test]
    fn corrupt_sizes_fail_cleanly_without_huge_allocations() {
        // Announced entries far beyond the file.
        let m = broken(
            "N.mtx",
            "%%MatrixMarket matrix coordinate real general\n1 3 1000000000000000\n1 2 1\n",
        );
        assert!(m.contains("only 1 entries"), "{m}");
        // Absurd dimensions that meta.json agrees with.
        let t = TempDir::new("huge");
        write_case(&t.0);
        std::fs::write(
            t.0.join("meta.json"),
            r#"{"n": 1000000000000, "p": 1, "F": 0.5, "alpha_start": 0, "alpha_end": 1}"#,
        )
        .unwrap();
        std::fs::write(
            t.0.join("A.mtx"),
            "%%MatrixMarket matrix coordinate real general\n1000000000000 1000000000000 1\n1 1 1\n",
        )
        .unwrap();
        let m = CaseData::read_dir(&t.0).unwrap_err().to_string();
        assert!(
            m.contains("A.mtx:2:") && m.contains("some row is empty"),
            "{m}"
        );
        // An empty row in N.
        let m = broken(
            "N.mtx",
            "%%MatrixMarket matrix coordinate real general\n1 3 0\n",
        );
        assert!(m.contains("some row is empty"), "{m}");
    }

    #[test]
    fn integral_floats_accepted_for_n_and_p() {
        let t = TempDir::new("float");
        write_case(&t.0);
        std::fs::write(
            t.0.join("meta.json"),
            r#"{"n": 3.0, "p": 1.0, "F": 0.5, "alpha_start": 0, "alpha_end": 1}"#,
        )
        .unwrap();
        let c = CaseData::read_dir(&t.0).unwrap();
        assert_eq!((c.n(), c.p()), (3, 1));
    }

    #[test]
    fn error_missing_file() {
        let t = TempDir::new("missing");
        write_case(&t.0);
        std::fs::remove_file(t.0.join("T.mtx")).unwrap();
        let m = CaseData::read_dir(&t.0).unwrap_err().to_string();
        assert!(m.contains("T.mtx") && m.contains("cannot read"), "{m}");
    }

    #[test]
    fn array_friction_and_gap_reach_the_problem_builder() {
        let t = TempDir::new("arr");
        write_case(&t.0);
        std::fs::write(
            t.0.join("meta.json"),
            r#"{"n": 3, "p": 1, "F": [1.25], "alpha_start": 0, "alpha_end": 1}"#,
        )
        .unwrap();
        std::fs::write(t.0.join("gap.txt"), "0.125\n").unwrap();
        let c = CaseData::read_dir(&t.0).unwrap();
        assert_eq!(c.friction, vec![1.25]);
        assert_eq!(c.gap, Some(vec![0.125]));
        let p = c.problem(Some(2.0)).unwrap();
        assert_eq!((p.n(), p.p()), (3, 1));
        assert_eq!(p.friction(), &[1.25]);
        assert_eq!(p.gap(), &[0.125]);
        assert_eq!(p.r(), 2.0);
        let p = c.problem(None).unwrap();
        assert_eq!(p.r(), p.default_r());
        assert_eq!(c.load().unwrap().n(), 3);
        // r <= 0 is the builder's error, passed through.
        assert!(c.problem(Some(0.0)).is_err());
    }
}
