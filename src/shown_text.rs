//! Text from files sapnet did not write (a folder's, a checkpoint's, a lock's) shown on a
//! terminal outside ratatui (errors, `sweep status`, `sources import`'s lines): as data,
//! never as the terminal's commands. A control character (an escape sequence's ESC, a
//! carriage return, a backspace) or a character that reorders what follows (bidirectional
//! overrides) is written escaped (`\u{1b}`); a list of thousands of received names is cut
//! with a count.

/// Whether `c` would act on a terminal rather than show: C0 and C1 controls, DEL, and the
/// bidirectional embeddings, overrides and isolates.
fn acts(c: char) -> bool {
    c.is_control() || matches!(c, '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}')
}

/// `text` with every character that would act on a terminal escaped (`\u{1b}`, `\n`),
/// line breaks included.
pub fn escaped(text: &str) -> String {
    escape(text, false)
}

/// [`escaped`], keeping line breaks: for a message of several lines.
pub fn escaped_lines(text: &str) -> String {
    escape(text, true)
}

fn escape(text: &str, keep_lines: bool) -> String {
    if !text.chars().any(acts) {
        return text.to_string();
    }
    let mut out = String::with_capacity(text.len() + 16);
    for c in text.chars() {
        if keep_lines && c == '\n' {
            out.push(c);
        } else if acts(c) {
            out.extend(c.escape_debug());
            // escape_debug leaves some format characters as they are.
            if !out.ends_with('}') && !out.ends_with(['n', 'r', 't', '0']) {
                out.pop();
                out.push_str(&format!("\\u{{{:x}}}", c as u32));
            }
        } else {
            out.push(c);
        }
    }
    out
}

/// `text`, escaped, cut at `chars` characters with what was left out counted.
pub fn cut(text: &str, chars: usize) -> String {
    let escaped = escaped(text);
    let total = escaped.chars().count();
    if total <= chars {
        return escaped;
    }
    let kept: String = escaped.chars().take(chars).collect();
    format!("{kept}… ({} more characters)", thousands(total - chars))
}

/// The first `shown` of `items`, joined by `, `, then "… and 199,990 more" for the rest.
pub fn cut_list<I>(items: I, shown: usize) -> String
where
    I: IntoIterator,
    I::Item: std::fmt::Display,
{
    let mut out = String::new();
    let mut left = 0_usize;
    for (i, item) in items.into_iter().enumerate() {
        if i >= shown {
            left += 1;
            continue;
        }
        if i > 0 {
            out.push_str(", ");
        }
        out.push_str(&item.to_string());
    }
    if left > 0 {
        out.push_str(&format!(" … and {} more", thousands(left)));
    }
    out
}

/// `n` with a comma between thousands: 199,990.
pub fn thousands(n: usize) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, d) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(d);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn control_characters_and_overrides_are_escaped() {
        assert_eq!(escaped("plain"), "plain");
        assert_eq!(
            escaped("a\u{1b}]0;pwned\u{7}b\u{1b}[2J"),
            "a\\u{1b}]0;pwned\\u{7}b\\u{1b}[2J"
        );
        assert_eq!(escaped("x\ny\rz\u{202e}"), "x\\ny\\rz\\u{202e}");
        assert_eq!(escaped_lines("x\ny\u{9b}"), "x\ny\\u{9b}");
        assert_eq!(escaped("\u{7f}"), "\\u{7f}");
    }

    #[test]
    fn long_text_and_long_lists_are_cut_with_a_count() {
        assert_eq!(thousands(199_990), "199,990");
        assert_eq!(thousands(12), "12");
        assert_eq!(thousands(1_000_000), "1,000,000");
        assert_eq!(cut_list(["a", "b"], 5), "a, b");
        let many = (0..200_000).map(|i| format!("m{i}"));
        assert_eq!(cut_list(many, 3), "m0, m1, m2 … and 199,997 more");
        assert_eq!(cut("abcdef", 4), "abcd… (2 more characters)");
        assert_eq!(cut("ab\u{1b}", 10), "ab\\u{1b}");
    }
}
