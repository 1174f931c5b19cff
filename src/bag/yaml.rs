//! Bounds on YAML read from files (machine descriptions, bag metadata), checked before the
//! parser sees the text: the parser's time grows faster than linearly with nesting (measured in
//! issue 15: 120 kB of nesting took 16 s), so size and nesting depth are limited first.

/// Deepest nesting accepted: flow brackets (`[`, `{`) open at once, or block indentation in
/// columns. A machine file nests 4 levels (some 10 columns); rosbag2 metadata some 12 columns.
pub const MAX_YAML_FLOW_DEPTH: usize = 32;
/// Deepest block indentation accepted (columns, counting `- ` sequence entries).
pub const MAX_YAML_INDENT: usize = 128;

/// Checks that `text` is at most `max_bytes` long and nests at most [`MAX_YAML_FLOW_DEPTH`]
/// brackets and [`MAX_YAML_INDENT`] columns deep; says which bound is broken, and on which line.
pub fn check_yaml_shape(text: &str, max_bytes: usize) -> Result<(), String> {
    if text.len() > max_bytes {
        return Err(format!(
            "is {} bytes, more than the {max_bytes} accepted",
            text.len()
        ));
    }
    let mut flow = 0usize;
    for (i, line) in text.lines().enumerate() {
        let indent = block_indent(line);
        if indent > MAX_YAML_INDENT {
            return Err(format!(
                "line {}: nested {indent} columns deep, more than the {MAX_YAML_INDENT} accepted",
                i + 1
            ));
        }
        let mut quote: Option<char> = None;
        for c in line.chars() {
            match (quote, c) {
                (Some(q), c) if c == q => quote = None,
                (Some(_), _) => {}
                (None, '"' | '\'') => quote = Some(c),
                (None, '#') => break,
                (None, '[' | '{') => flow += 1,
                (None, ']' | '}') => flow = flow.saturating_sub(1),
                _ => {}
            }
            if flow > MAX_YAML_FLOW_DEPTH {
                return Err(format!(
                    "line {}: more than {MAX_YAML_FLOW_DEPTH} brackets open at once",
                    i + 1
                ));
            }
        }
    }
    Ok(())
}

/// Indentation of a block line in columns, sequence entries (`- - x`) counted as indentation.
fn block_indent(line: &str) -> usize {
    let mut col = 0;
    let bytes = line.as_bytes();
    while col < bytes.len() {
        match bytes[col] {
            b' ' => col += 1,
            b'-' if matches!(bytes.get(col + 1), Some(b' ') | None) => col += 1,
            _ => break,
        }
    }
    col
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ordinary_yaml_passes_and_deep_nesting_is_refused_before_parsing() {
        let ok = "a:\n  b: [1, 2, {c: 3}]\n  d:\n    - e: 'x [ y'\n";
        assert_eq!(check_yaml_shape(ok, 1000), Ok(()));
        let flow = format!("a: {}{}", "[".repeat(33), "]".repeat(33));
        assert!(check_yaml_shape(&flow, 1 << 20).is_err());
        let mut block = String::new();
        for d in 0..70 {
            block += &format!("{}a{d}:\n", "  ".repeat(d));
        }
        let e = check_yaml_shape(&block, 1 << 20).unwrap_err();
        assert!(e.contains("line 66"), "{e}");
        let dashes = format!("{}x\n", "- ".repeat(65));
        assert!(check_yaml_shape(&dashes, 1 << 20).is_err());
        assert!(check_yaml_shape(ok, 10).unwrap_err().contains("bytes"));
    }
}
