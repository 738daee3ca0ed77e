//! Short names for policies and tasks, where a graph node or a table column has a few
//! characters for them.

/// `cartpole(length=1.0)` → `length=1.0`: a source task's label without its family, for a
/// library whose tasks are variants of one; other labels (a label written in words, such
/// as `sees (θ, dθ, x, dx)`) stay as they are.
pub fn short_task(label: &str) -> &str {
    match label.split_once('(') {
        Some((family, rest)) if !family.contains(' ') && rest.ends_with(')') => {
            &rest[..rest.len() - 1]
        }
        _ => label,
    }
}

/// The nodes' labels: [`short_label`]s where they tell every policy apart, else the index
/// in the paper's notation, π0…πN−1 (the tables give the names).
pub fn labels(names: &[String]) -> Vec<String> {
    distinct_labels(names).unwrap_or_else(|| (0..names.len()).map(|i| format!("π{i}")).collect())
}

/// The [`short_label`] of each name, if no two are the same: `source-3`, `source-12` →
/// `3`, `12`; not `1×100`, `2×100` (both `100`).
pub fn distinct_labels(names: &[String]) -> Option<Vec<String>> {
    let labels: Vec<String> = names.iter().map(|n| short_label(n)).collect();
    let mut sorted: Vec<&String> = labels.iter().collect();
    sorted.sort_unstable();
    sorted.dedup();
    (sorted.len() == labels.len()).then_some(labels)
}

/// `source-12` → `12`; short names stay as they are.
pub fn short_label(name: &str) -> String {
    let digits = name.len() - name.trim_end_matches(|c: char| c.is_ascii_digit()).len();
    if digits > 0 && name.len() - digits > 2 {
        name[name.len() - digits..].to_string()
    } else {
        name.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_task_loses_its_family_but_a_label_in_words_stays_whole() {
        assert_eq!(short_task("cartpole(length=1.0)"), "length=1.0");
        assert_eq!(short_task("LunarLander-v3(gravity=-6.0)"), "gravity=-6.0");
        assert_eq!(short_task("sees (θ, dθ, x, dx)"), "sees (θ, dθ, x, dx)");
        assert_eq!(short_task("mirrored"), "mirrored");
    }

    #[test]
    fn labels_keep_the_number_of_long_names() {
        assert_eq!(short_label("source-12"), "12");
        assert_eq!(short_label("π3"), "π3");
        assert_eq!(short_label("cartpole"), "cartpole");
    }

    #[test]
    fn names_whose_numbers_repeat_are_labelled_by_index() {
        let names = |list: &[&str]| list.iter().map(ToString::to_string).collect::<Vec<_>>();
        assert_eq!(labels(&names(&["source-0", "source-12"])), ["0", "12"]);
        // Table II's lesson: three names end in 100.
        assert_eq!(
            labels(&names(&["1×100", "2×100", "2×64-128", "3×50-150-100"])),
            ["π0", "π1", "π2", "π3"]
        );
    }
}
