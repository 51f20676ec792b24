//! The lines of an OBJ or MTL file as exporters write them: CRLF or LF line ends, blanks or tabs
//! before and between tokens, comments on their own line or after a statement
//! (`Ka 0.63 0.065 0.05 # Red`). Both parsers read their files through [`statements`], so the
//! rules are the same everywhere; and both count the statements they skip in a [`Skipped`].

use std::collections::BTreeMap;

/// One statement: its keyword and what follows it, comment and outer blanks removed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Statement<'a> {
    /// 1-based line number, for messages.
    pub line: usize,
    pub keyword: &'a str,
    /// The rest of the line, trimmed ("" when there is none).
    pub rest: &'a str,
}

impl<'a> Statement<'a> {
    /// The rest split at blanks and tabs.
    pub fn tokens(&self) -> std::str::SplitWhitespace<'a> {
        self.rest.split_whitespace()
    }
}

/// The statements of `text`, in order. A `#` at the start of a line or after a blank begins a
/// comment that runs to the end of the line; a `#` inside a token (`Material#1`) does not.
/// `str::lines` already drops the `\r` of a CRLF line end.
pub(super) fn statements(text: &str) -> impl Iterator<Item = Statement<'_>> {
    text.lines().enumerate().filter_map(|(n, line)| {
        let line = without_comment(line).trim();
        if line.is_empty() {
            return None;
        }
        let (keyword, rest) = match line.find(char::is_whitespace) {
            Some(i) => (&line[..i], line[i..].trim()),
            None => (line, ""),
        };
        Some(Statement {
            line: n + 1,
            keyword,
            rest,
        })
    })
}

fn without_comment(line: &str) -> &str {
    let mut previous_blank = true;
    for (i, c) in line.char_indices() {
        if c == '#' && previous_blank {
            return &line[..i];
        }
        previous_blank = c.is_whitespace();
    }
    line
}

/// Exactly three numbers, or `None`.
pub(super) fn three_numbers(s: &Statement) -> Option<[f32; 3]> {
    let mut tokens = s.tokens();
    let mut out = [0.0; 3];
    for v in &mut out {
        *v = tokens.next()?.parse().ok()?;
    }
    tokens.next().is_none().then_some(out)
}

/// How many statements of each keyword a parser skipped, for one summary line per file.
#[derive(Debug, Default)]
pub(super) struct Skipped {
    counts: BTreeMap<String, usize>,
    total: usize,
}

/// Distinct keywords remembered by name; more (a file of junk) are counted as "other". Keeps the
/// tally small whatever the file holds.
const KEYWORDS_KEPT: usize = 64;
/// Longest keyword echoed in the summary.
const KEYWORD_SHOWN: usize = 24;

impl Skipped {
    pub fn add(&mut self, keyword: &str) {
        self.total += 1;
        if let Some(n) = self.counts.get_mut(keyword) {
            *n += 1;
        } else if self.counts.len() < KEYWORDS_KEPT {
            self.counts.insert(keyword.to_string(), 1);
        }
    }

    #[cfg(test)]
    pub fn total(&self) -> usize {
        self.total
    }

    /// `skipped 40 statements the solver does not use (Ka ×8, Ks ×8, ...)`, most frequent first;
    /// `None` when nothing was skipped.
    pub fn summary(&self) -> Option<String> {
        if self.total == 0 {
            return None;
        }
        let mut counts: Vec<(&String, &usize)> = self.counts.iter().collect();
        counts.sort_by(|a, b| b.1.cmp(a.1).then(a.0.cmp(b.0)));
        let mut parts: Vec<String> = counts
            .iter()
            .take(10)
            .map(|(k, n)| {
                let k: String = k.chars().take(KEYWORD_SHOWN).collect();
                format!("{} ×{n}", super::shown(&k))
            })
            .collect();
        let listed: usize = counts.iter().take(10).map(|(_, n)| **n).sum();
        if listed < self.total {
            let others = self.total - listed;
            let s = if others == 1 { "" } else { "s" };
            parts.push(format!("{others} other{s}"));
        }
        let s = if self.total == 1 { "" } else { "s" };
        Some(format!(
            "skipped {} statement{s} the solver does not use ({})",
            self.total,
            parts.join(", ")
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exporters_spacing_and_comments() {
        let text = "# header\r\n\tKa 0.63\t0.065 0.05 # Red\r\n\r\n  newmtl  Material#1 \r\nillum";
        let s: Vec<Statement> = statements(text).collect();
        assert_eq!(s.len(), 3);
        assert_eq!(
            (s[0].line, s[0].keyword, s[0].rest),
            (2, "Ka", "0.63\t0.065 0.05")
        );
        assert_eq!(three_numbers(&s[0]), Some([0.63, 0.065, 0.05]));
        assert_eq!(
            (s[1].line, s[1].keyword, s[1].rest),
            (4, "newmtl", "Material#1")
        );
        assert_eq!((s[2].line, s[2].keyword, s[2].rest), (5, "illum", ""));
    }

    #[test]
    fn three_numbers_means_three() {
        let one = |t: &str| statements(t).next().map(|s| three_numbers(&s));
        assert_eq!(one("Kd 1 2 3"), Some(Some([1.0, 2.0, 3.0])));
        for bad in ["Kd 1 2", "Kd 1 2 3 4", "Kd 1 x 3", "Kd"] {
            assert_eq!(one(bad), Some(None), "{bad}");
        }
    }

    #[test]
    fn the_summary_counts_every_statement_and_lists_the_most_frequent() {
        let mut skipped = Skipped::default();
        assert_eq!(skipped.summary(), None);
        for k in ["Ka", "Ks", "Ka", "illum", "\x1b[2J"] {
            skipped.add(k);
        }
        assert_eq!(
            skipped.summary().unwrap(),
            "skipped 5 statements the solver does not use (Ka ×2, \\u{1b}[2J ×1, Ks ×1, illum ×1)"
        );
        let mut many = Skipped::default();
        for k in 0..100 {
            many.add(&format!("k{k:03}"));
        }
        let s = many.summary().unwrap();
        assert!(s.starts_with("skipped 100 statements"), "{s}");
        assert!(s.ends_with("k009 ×1, 90 others)"), "{s}");
    }
}
