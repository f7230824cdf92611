//! The XDMF description of a simulation run's particle history, `<run_id>.xdmf` beside its
//! run file, which ParaView opens with its XDMF reader (VTK's `vtkXdmfReader`). It copies no
//! data: a temporal collection holds one grid per sample, a Polyvertex of the particles, whose
//! geometry and attributes are HyperSlabs of that sample in the run file's datasets, named by
//! the run file's name (relative, so a results directory can be moved) and dataset path.

use std::io;
use std::path::{Path, PathBuf};

use super::{write_atomically, RunRecord, Unstepped, ERROR_FIELDS};

/// What a description needs to know of a run file: the shape of its per-sample datasets and
/// the sample times.
#[derive(Clone, Debug, PartialEq)]
pub struct HistoryLayout {
    pub dim: usize,
    pub particles: usize,
    /// `/history/time`.
    pub time: Vec<f64>,
}

impl HistoryLayout {
    /// `None` for a run without a particle history: an unstepped run, or one that failed
    /// before its first sample.
    pub fn of(record: &RunRecord) -> Option<HistoryLayout> {
        if !matches!(record.unstepped, Unstepped::None) {
            return None;
        }
        HistoryLayout {
            dim: record.dim,
            particles: record.particles.len(),
            time: record.history.time.clone(),
        }
        .nonempty()
    }

    /// The same, from a written run file.
    pub fn read(path: &Path) -> hdf5::Result<Option<HistoryLayout>> {
        let file = hdf5::File::open(path)?;
        if !file.link_exists("history") {
            return Ok(None);
        }
        let shape = file.dataset("particles/X")?.shape();
        let &[particles, dim] = shape.as_slice() else {
            return Err(format!("/particles/X has shape {shape:?}, not (Np, D)").into());
        };
        let time = file.dataset("history/time")?.read_raw::<f64>()?;
        Ok(HistoryLayout {
            dim,
            particles,
            time,
        }
        .nonempty())
    }

    fn nonempty(self) -> Option<HistoryLayout> {
        (self.particles > 0 && !self.time.is_empty()).then_some(self)
    }
}

/// The description's path: the run file's with the extension `xdmf`.
pub fn xdmf_path(run_file: &Path) -> PathBuf {
    run_file.with_extension("xdmf")
}

/// Writes the description of `run_file` under a temporary name and renames it into place.
pub fn write_xdmf(run_file: &Path, layout: &HistoryLayout) -> io::Result<()> {
    let name = run_file
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    write_atomically(&xdmf_path(run_file), |tmp| {
        let mut out = io::BufWriter::new(std::fs::File::create(tmp)?);
        write_description(&mut out, &name, layout)?;
        io::Write::flush(&mut out)
    })
}

/// How one particle's value of a dataset is shaped.
#[derive(Clone, Copy)]
enum Rank {
    Scalar,
    Vector,
    Tensor,
}

/// The attributes of each grid: every per-sample, per-particle dataset of a run file.
fn attributes() -> Vec<(String, String, Rank)> {
    let mut fields = vec![
        ("position".into(), "/history/x".into(), Rank::Vector),
        ("velocity".into(), "/history/v".into(), Rank::Vector),
        ("stress".into(), "/history/stress".into(), Rank::Tensor),
        ("density".into(), "/history/density".into(), Rank::Scalar),
        ("volume".into(), "/errors/volume".into(), Rank::Scalar),
    ];
    for field in ERROR_FIELDS {
        fields.push((
            format!("{field}_error"),
            format!("/errors/{field}"),
            Rank::Scalar,
        ));
    }
    fields
}

/// Writes the XDMF text for the run file named `run_file` (relative to the description) one
/// sample's grid at a time, so that its memory does not grow with
/// the samples.
fn write_description(
    out: &mut impl io::Write,
    run_file: &str,
    layout: &HistoryLayout,
) -> io::Result<()> {
    let collection = Element::new("Grid")
        .attr("Name", run_file.strip_suffix(".h5").unwrap_or(run_file))
        .attr("GridType", "Collection")
        .attr("CollectionType", "Temporal");
    let outer = [
        Element::new("Xdmf").attr("Version", "2.0"),
        Element::new("Domain"),
        collection,
    ];
    let mut text = String::from("<?xml version=\"1.0\" ?>\n");
    for (depth, element) in outer.iter().enumerate() {
        element.open(&mut text, depth);
    }
    for (sample, &time) in layout.time.iter().enumerate() {
        sample_grid(run_file, layout, sample, time).write(&mut text, outer.len());
        out.write_all(text.as_bytes())?;
        text.clear();
    }
    for (depth, element) in outer.iter().enumerate().rev() {
        element.close(&mut text, depth);
    }
    out.write_all(text.as_bytes())
}

/// The grid of one sample: the particles at `time` as a Polyvertex with every attribute.
fn sample_grid(run_file: &str, layout: &HistoryLayout, sample: usize, time: f64) -> Element {
    let (np, d) = (layout.particles, layout.dim);
    let slab = Slab {
        file: run_file,
        samples: layout.time.len(),
        sample,
        particles: np,
        dim: d,
    };
    let position = slab.item("/history/x", Rank::Vector);
    let geometry = match d {
        // A bar lies on the x axis: y = z = 0 times its x.
        1 => {
            let zero = Element::new("DataItem")
                .attr("ItemType", "Function")
                .attr("Function", "0 * $0")
                .attr("Dimensions", np)
                .child(position.clone());
            Element::new("Geometry")
                .attr("GeometryType", "X_Y_Z")
                .child(position)
                .child(zero.clone())
                .child(zero)
        }
        _ => Element::new("Geometry")
            .attr("GeometryType", if d == 2 { "XY" } else { "XYZ" })
            .child(position),
    };
    let mut grid = Element::new("Grid")
        .attr("Name", format!("sample {sample}"))
        .attr("GridType", "Uniform")
        // Debug formatting is the shortest text that reads back as the same f64.
        .child(Element::new("Time").attr("Value", format!("{time:?}")))
        .child(
            Element::new("Topology")
                .attr("TopologyType", "Polyvertex")
                .attr("NumberOfElements", np)
                .attr("NodesPerElement", 1),
        )
        .child(geometry);
    for (name, path, rank) in attributes() {
        grid = grid.child(
            Element::new("Attribute")
                .attr("Name", name)
                .attr("AttributeType", attribute_type(rank, d))
                .attr("Center", "Node")
                .child(slab.item(&path, rank)),
        );
    }
    grid
}

/// One sample of a (samples x particles x components) dataset.
struct Slab<'a> {
    file: &'a str,
    samples: usize,
    sample: usize,
    particles: usize,
    dim: usize,
}

impl Slab<'_> {
    /// A HyperSlab DataItem: start (sample, 0, ...), stride 1, count (1, particles,
    /// components), read as (particles) in 1D, where every component axis has length one,
    /// and as (particles, components) otherwise.
    fn item(&self, path: &str, rank: Rank) -> Element {
        let components: &[usize] = match rank {
            Rank::Scalar => &[],
            Rank::Vector => &[self.dim],
            Rank::Tensor => &[self.dim, self.dim],
        };
        let mut full = vec![self.samples, self.particles];
        full.extend(components);
        let mut start = vec![0; full.len()];
        start[0] = self.sample;
        let stride = vec![1; full.len()];
        let mut count = vec![1, self.particles];
        count.extend(components);
        let mut read = vec![self.particles];
        if self.dim > 1 {
            read.extend(components);
        }
        let selection = Element::new("DataItem")
            .attr("Dimensions", format!("3 {}", full.len()))
            .attr("Format", "XML")
            .text(format!(
                "{} {} {}",
                join(&start),
                join(&stride),
                join(&count)
            ));
        let data = Element::new("DataItem")
            .attr("Dimensions", join(&full))
            .attr("NumberType", "Float")
            .attr("Precision", 8)
            .attr("Format", "HDF")
            .text(format!("{}:{path}", self.file));
        Element::new("DataItem")
            .attr("ItemType", "HyperSlab")
            .attr("Dimensions", join(&read))
            .child(selection)
            .child(data)
    }
}

/// VTK's reader makes a Vector of 2 components into 3 (z = 0) and reads a Matrix of
/// (particles, D, D) as D*D components per particle; in 1D every field is a Scalar.
fn attribute_type(rank: Rank, dim: usize) -> &'static str {
    match rank {
        _ if dim == 1 => "Scalar",
        Rank::Scalar => "Scalar",
        Rank::Vector => "Vector",
        Rank::Tensor => "Matrix",
    }
}

fn join(values: &[usize]) -> String {
    values
        .iter()
        .map(usize::to_string)
        .collect::<Vec<_>>()
        .join(" ")
}

/// An XML element with either children or text, written indented one level per depth.
#[derive(Clone)]
struct Element {
    name: &'static str,
    attributes: Vec<(&'static str, String)>,
    children: Vec<Element>,
    text: String,
}

impl Element {
    fn new(name: &'static str) -> Element {
        Element {
            name,
            attributes: Vec::new(),
            children: Vec::new(),
            text: String::new(),
        }
    }

    fn attr(mut self, key: &'static str, value: impl ToString) -> Element {
        self.attributes.push((key, value.to_string()));
        self
    }

    fn child(mut self, child: Element) -> Element {
        self.children.push(child);
        self
    }

    fn text(mut self, text: String) -> Element {
        self.text = text;
        self
    }

    fn write(&self, out: &mut String, depth: usize) {
        if !self.text.is_empty() {
            self.start(out, depth);
            out.push_str(&format!(">{}</{}>\n", escape(&self.text), self.name));
        } else if self.children.is_empty() {
            self.start(out, depth);
            out.push_str("/>\n");
        } else {
            self.open(out, depth);
            for child in &self.children {
                child.write(out, depth + 1);
            }
            self.close(out, depth);
        }
    }

    /// `<name attributes`, indented.
    fn start(&self, out: &mut String, depth: usize) {
        out.push_str(&"  ".repeat(depth));
        out.push('<');
        out.push_str(self.name);
        for (key, value) in &self.attributes {
            out.push_str(&format!(" {key}=\"{}\"", escape(value)));
        }
    }

    /// The start tag of an element whose children follow.
    fn open(&self, out: &mut String, depth: usize) {
        self.start(out, depth);
        out.push_str(">\n");
    }

    fn close(&self, out: &mut String, depth: usize) {
        out.push_str(&format!("{}</{}>\n", "  ".repeat(depth), self.name));
    }
}

fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::{describe_if_missing, write_run};

    /// The XDMF text for the run file named `run_file`.
    fn describe(run_file: &str, layout: &HistoryLayout) -> String {
        let mut out = Vec::new();
        write_description(&mut out, run_file, layout).unwrap();
        String::from_utf8(out).unwrap()
    }

    /// A small run of `yaml`'s first configuration, written into `dir`.
    fn written_run(dir: &Path, yaml: &str) -> (RunRecord, PathBuf) {
        let exp = crate::experiment::parse(yaml, Path::new("t.yaml")).unwrap();
        let record = crate::solver::simulate(&exp.runs[0]);
        let path = write_run(dir, &record).unwrap();
        (record, path)
    }

    fn numbers(text: &str) -> Vec<usize> {
        text.split_whitespace()
            .map(|n| n.parse().unwrap())
            .collect()
    }

    /// The description names only datasets of the run file, with their shapes, selects one
    /// sample of each within its bounds, and holds the sample times exactly.
    fn check_description(record: &RunRecord, run_file: &Path) {
        let text = std::fs::read_to_string(xdmf_path(run_file)).unwrap();
        let doc = roxmltree::Document::parse(&text).expect("well-formed XML");
        let file = hdf5::File::open(run_file).unwrap();
        let name = run_file.file_name().unwrap().to_str().unwrap();
        let (np, d) = (record.particles.len(), record.dim);
        let collection = doc
            .descendants()
            .find(|n| n.attribute("CollectionType") == Some("Temporal"))
            .unwrap();
        let grids: Vec<_> = collection
            .children()
            .filter(|n| n.has_tag_name("Grid"))
            .collect();
        assert_eq!(grids.len(), record.history.time.len());
        for (sample, grid) in grids.iter().enumerate() {
            let time = grid.children().find(|n| n.has_tag_name("Time")).unwrap();
            let value: f64 = time.attribute("Value").unwrap().parse().unwrap();
            assert_eq!(value.to_bits(), record.history.time[sample].to_bits());
            let topology = grid
                .children()
                .find(|n| n.has_tag_name("Topology"))
                .unwrap();
            assert_eq!(topology.attribute("TopologyType"), Some("Polyvertex"));
            assert_eq!(
                topology.attribute("NumberOfElements"),
                Some(np.to_string().as_str())
            );
            let names: Vec<_> = grid
                .children()
                .filter(|n| n.has_tag_name("Attribute"))
                .map(|n| n.attribute("Name").unwrap())
                .collect();
            for field in ["position", "velocity", "stress", "density", "stress_error"] {
                assert!(names.contains(&field), "{field} missing from {names:?}");
            }
            for slab in grid
                .descendants()
                .filter(|n| n.attribute("ItemType") == Some("HyperSlab"))
            {
                let items: Vec<_> = slab.children().filter(|n| n.is_element()).collect();
                let [selection, data] = items.as_slice() else {
                    panic!("a HyperSlab holds a selection and a dataset");
                };
                let (source, path) = data.text().unwrap().split_once(':').unwrap();
                assert_eq!(source, name, "the run file by its relative name");
                let shape = file.dataset(path).unwrap().shape();
                assert_eq!(
                    numbers(data.attribute("Dimensions").unwrap()),
                    shape,
                    "{path}"
                );
                let selected = numbers(selection.text().unwrap());
                let (start, rest) = selected.split_at(shape.len());
                let (stride, count) = rest.split_at(shape.len());
                assert_eq!(start[0], sample, "{path}");
                assert!(start[1..].iter().all(|&s| s == 0) && stride.iter().all(|&s| s == 1));
                assert_eq!(count[0], 1);
                assert_eq!(&count[1..], &shape[1..], "{path}: one whole sample");
                let read = numbers(slab.attribute("Dimensions").unwrap());
                assert_eq!(read[0], np);
                assert_eq!(
                    read.iter().product::<usize>(),
                    count.iter().product::<usize>()
                );
            }
            let geometry = grid
                .children()
                .find(|n| n.has_tag_name("Geometry"))
                .unwrap();
            let kind = if d == 1 { "X_Y_Z" } else { "XY" };
            assert_eq!(geometry.attribute("GeometryType"), Some(kind));
        }
    }

    #[test]
    fn describes_1d_and_2d_histories_and_is_rewritten_when_missing() {
        let tmp = tempfile::tempdir().unwrap();
        for yaml in [
            "name: t\nbenchmark: mms1d_gong\nparams: {method: mpm, G: 1.0e-4, cells: 4, ppc: 2}\n\
             output: {every: 4}\n",
            "name: t\nbenchmark: mms2d_gong\nparams: {method: mpm, G: 1.0e-4, cells: 4, ppc: 1}\n\
             output: {every: 4}\n",
        ] {
            let (record, run_file) = written_run(tmp.path(), yaml);
            assert!(
                record.history.time.len() >= 3,
                "{}",
                record.history.time.len()
            );
            check_description(&record, &run_file);
            assert_eq!(
                HistoryLayout::read(&run_file).unwrap(),
                HistoryLayout::of(&record)
            );
            let written = std::fs::read(xdmf_path(&run_file)).unwrap();
            std::fs::remove_file(xdmf_path(&run_file)).unwrap();
            describe_if_missing(&run_file).unwrap();
            assert_eq!(std::fs::read(xdmf_path(&run_file)).unwrap(), written);
        }
    }

    #[test]
    fn a_run_without_particles_has_no_description() {
        let tmp = tempfile::tempdir().unwrap();
        let yaml = "name: t\nbenchmark: recon1d_nodes\n\
                    params: {method: shepard, function: x, cells: 10, ppc: 2}\n";
        let (record, run_file) = written_run(tmp.path(), yaml);
        assert_eq!(HistoryLayout::of(&record), None);
        assert_eq!(HistoryLayout::read(&run_file).unwrap(), None);
        describe_if_missing(&run_file).unwrap();
        assert!(!xdmf_path(&run_file).exists());
    }

    #[test]
    fn names_are_escaped() {
        let layout = HistoryLayout {
            dim: 1,
            particles: 2,
            time: vec![0.0, 0.1],
        };
        let text = describe("a&b<\"c\">.h5", &layout);
        let doc = roxmltree::Document::parse(&text).unwrap();
        let root = doc.root_element();
        let collection = root.first_element_child().unwrap().first_element_child();
        assert_eq!(collection.unwrap().attribute("Name"), Some("a&b<\"c\">"));
    }
}
