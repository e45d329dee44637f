//! Short renderings for error messages: numbers, quoted input and header lists stay a line
//! long whatever the input, and a guess at the format of a file that is not CSV.

fn ordinary(v: f64) -> bool {
    let a = v.abs();
    a == 0.0 || (1e-3..1e6).contains(&a) || !a.is_finite()
}

/// A number as written when that is short (`0.001`), else in at most seven significant
/// digits (`1.0e300`, not three hundred digits).
pub fn short(v: f64) -> String {
    let s = format!("{v}");
    if s.len() <= 10 {
        s
    } else if ordinary(v) {
        let f = format!("{v:.7}");
        f.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{v:.6e}")
    }
}

/// Four decimals for ordinary magnitudes, else four-digit scientific notation.
pub fn fixed4(v: f64) -> String {
    if ordinary(v) {
        format!("{v:.4}")
    } else {
        format!("{v:.4e}")
    }
}

/// Input text quoted for a message, cut after 24 characters.
pub fn quote(s: &str) -> String {
    const MAX: usize = 24;
    let n = s.chars().count();
    if n <= MAX {
        format!("`{s}`")
    } else {
        let head: String = s.chars().take(MAX).collect();
        format!("`{head}...` ({n} characters)")
    }
}

/// Header names for a message: at most 12, each cut.
pub fn names(v: &[String]) -> String {
    let mut out: Vec<String> = v
        .iter()
        .take(12)
        .map(|n| {
            let q = quote(n);
            q[1..q.len() - 1].to_string()
        })
        .collect();
    if v.len() > 12 {
        out.push(format!("... ({} columns)", v.len()));
    }
    out.join(", ")
}

/// When a header cannot be read and the extension or the content suggests another format:
/// which format was assumed, and what the content looks like (else nothing).
pub fn format_hint(file: &str, text: &str) -> String {
    let ext = std::path::Path::new(file)
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    let first = text
        .lines()
        .map(str::trim)
        .find(|l| !l.is_empty() && !l.starts_with('#'))
        .unwrap_or("");
    let looks = if first.starts_with('{') || (first.starts_with('[') && first.contains('"')) {
        Some("JSON")
    } else if first.starts_with('[') || first.contains('=') {
        Some("TOML")
    } else if !first.contains(',') && first.contains(';') {
        Some("CSV with `;` separators")
    } else if !first.contains(',') && first.contains('\t') {
        Some("tab-separated values")
    } else {
        None
    };
    let odd_ext = ext
        .as_deref()
        .filter(|e| !matches!(*e, "csv" | "txt" | "dat"));
    if odd_ext.is_none() && looks.is_none() {
        return String::new();
    }
    let mut hint = String::from("; the file was read as CSV (comma-separated, header first)");
    if let Some(e) = odd_ext {
        hint.push_str(&format!(", whatever its extension `.{e}`"));
    }
    if let Some(l) = looks {
        hint.push_str(&format!(", but its content looks like {l}"));
    }
    hint
}
