//! results/README.md, the front page of the results: every paper claim of every experiment
//! with ours and a verdict, the verdict counts, and the figures that reproduce each paper
//! item, all from the experiments and their run files.

use std::collections::BTreeMap;
use std::fmt::Write;
use std::path::Path;

use super::claims::{claim_figures, Outcome, Verdict, COLUMNS};
use super::figures::{FieldMap, Figure};
use super::markdown::table;
use crate::experiment::Experiment;

/// What the index shows of one experiment: its directory under the results root, and what
/// its report computes.
pub struct Indexed<'a> {
    pub dir: &'a str,
    pub experiment: &'a Experiment,
    pub claims: Vec<Outcome<'a>>,
    pub figures: Vec<Figure>,
    pub maps: Vec<FieldMap>,
    /// How many of its run files its report could not read (and lists).
    pub unreadable_runs: usize,
}

/// A results directory the index leaves out: its experiment copy cannot be read, or its
/// report cannot be planned.
pub struct Unreadable<'a> {
    pub dir: &'a str,
    pub reason: String,
}

const VERDICTS: [Verdict; 5] = [
    Verdict::Reproduced,
    Verdict::Differs,
    Verdict::Unexplained,
    Verdict::Stale,
    Verdict::Unmeasured,
];

pub fn index_md(experiments: &[Indexed], unreadable: &[Unreadable]) -> String {
    let mut md = String::from(
        "# Reproduction index\n\nWritten by `mpmlab index` (`make all`) from `experiments/*.yaml` \
         and the run files: every number a paper states (each experiment's `paper_claims`), \
         ours beside it, and the verdict; then the figures that reproduce each paper item. \
         A claim is reproduced when every measured value is within its tolerance (absolute \
         for a rate, relative for an error); a difference cites the item of docs/NOTES.md \
         that isolates its cause. `mpmlab report --check` fails on a claim that differs \
         without one.\n\n## Verdicts\n\n",
    );
    let all: Vec<&Outcome> = experiments.iter().flat_map(|e| &e.claims).collect();
    let counts = VERDICTS.iter().map(|v| {
        let n = all.iter().filter(|o| o.verdict == *v).count();
        vec![v.as_str().to_string(), n.to_string()]
    });
    table(&mut md, &["verdict".into(), "claims".into()], counts);
    claims_by_paper(&mut md, experiments);
    figures_by_item(&mut md, experiments);
    md.push_str("## Experiments\n\n");
    for e in experiments {
        let _ = write!(
            md,
            "- [{}]({}/report.md): {} runs",
            e.experiment.name,
            e.dir,
            e.experiment.runs.len()
        );
        let _ = match e.unreadable_runs {
            0 => writeln!(md),
            n => writeln!(md, "; {n} unreadable run file(s), listed in its report"),
        };
    }
    if !unreadable.is_empty() {
        md.push_str("\n## Unreadable results directories\n\nLeft out of everything above:\n\n");
        for u in unreadable {
            let _ = writeln!(md, "- `{}`: {}", u.dir, u.reason.replace('\n', " "));
        }
    }
    md
}

/// The paper an item belongs to: what comes before its first comma ("Gong 2015").
fn paper_of(item: &str) -> &str {
    item.split(',').next().unwrap_or(item).trim()
}

fn claims_by_paper(md: &mut String, experiments: &[Indexed]) {
    let mut papers: BTreeMap<&str, Vec<Vec<String>>> = BTreeMap::new();
    for e in experiments {
        for o in &e.claims {
            let figures: Vec<&Figure> = claim_figures(o, &e.figures).collect();
            let maps = e
                .maps
                .iter()
                .filter(|m| o.claim.figure.is_some() && m.drawn_by == o.claim.figure);
            let files = figures.iter().map(|f| &f.file).chain(maps.map(|m| &m.file));
            let mut row = o.cells(links(e.dir, files));
            row.push(format!("[{}]({}/report.md)", e.experiment.name, e.dir));
            papers.entry(paper_of(&o.claim.item)).or_default().push(row);
        }
    }
    let mut header = COLUMNS.map(String::from).to_vec();
    header.push("experiment".into());
    for (paper, rows) in papers {
        let _ = writeln!(md, "## {paper}: claims\n");
        table(md, &header, rows.into_iter());
    }
}

/// Every figure whose item names the paper figure it reproduces, by that paper figure.
fn figures_by_item(md: &mut String, experiments: &[Indexed]) {
    let mut items: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for e in experiments {
        for spec in &e.experiment.figures {
            let (Some(paper), Some(name)) = (&spec.paper, &spec.name) else {
                continue;
            };
            let drawn = |by: &Option<String>| by.as_deref() == Some(name.as_str());
            let files = e
                .figures
                .iter()
                .filter(|f| drawn(&f.drawn_by))
                .map(|f| &f.file)
                .chain(
                    e.maps
                        .iter()
                        .filter(|m| drawn(&m.drawn_by))
                        .map(|m| &m.file),
                );
            let title = spec.title.as_deref().unwrap_or(name);
            let entry = format!("{title} ({}): {}", e.experiment.name, links(e.dir, files));
            items.entry(paper.clone()).or_default().push(entry);
        }
    }
    md.push_str("## Figures by paper item\n\n");
    for (item, entries) in items {
        let _ = writeln!(md, "- **{item}**");
        for entry in entries {
            let _ = writeln!(md, "  - {entry}");
        }
    }
    md.push('\n');
}

/// Links to figure files of the experiment in `dir`, named by their stems.
fn links<'a>(dir: &str, files: impl Iterator<Item = &'a std::path::PathBuf>) -> String {
    let links: Vec<String> = files
        .map(|file| {
            let stem = file.file_stem().unwrap_or_default().to_string_lossy();
            let path = Path::new(dir).join(file);
            format!("[{stem}]({})", path.to_string_lossy().replace('\\', "/"))
        })
        .collect();
    links.join(", ")
}

#[cfg(test)]
mod tests {
    use super::paper_of;

    #[test]
    fn items_belong_to_the_paper_before_their_comma() {
        assert_eq!(paper_of("Gong 2015, Fig 4.7"), "Gong 2015");
        assert_eq!(paper_of("Molinos et al., Fig 10"), "Molinos et al.");
        assert_eq!(paper_of("Table 3"), "Table 3");
    }
}
