//! The arrays of a simulation run that grow with its samples and steps, written to its run file
//! as they are recorded: datasets chunked along their first axis and extended by each append,
//! so that a run holds at most one chunk of each in memory whatever its number of samples. A
//! record kept in memory is written through the same appends, so both give the same datasets.

use hdf5::{Dataset, Extent, Group, H5Type, Hyperslab, SimpleExtents, SliceOrIndex};
use ndarray::{ArrayView, IxDyn};

use super::h5::{attr_str, dataset};
use super::probes::{self, WiggleTally};
use super::{Errors, GridHistory, History, ProbeRecord, Wiggles, ERROR_FIELDS, GRID_VELOCITY};

/// About 1 MiB of float64 per chunk: large enough that a write per chunk costs little, small
/// enough that the buffers of a run's 15 or so arrays stay far below its particle state.
const CHUNK_VALUES: usize = 1 << 17;

/// HDF5 refuses chunks of 4 GiB or more; a row of a 10^8-particle 2D stress (3.2 GB) stays
/// below this bound, which splits larger rows along their second axis.
const MAX_CHUNK_BYTES: usize = 1 << 31;

/// A dataset of rows of a fixed shape that grows along its first axis.
#[derive(Debug)]
struct Appender<T> {
    group: Group,
    name: String,
    unit: &'static str,
    row_shape: Vec<usize>,
    /// Values per row.
    row: usize,
    /// None until the first write, and for rows of no values, whose dataset `finish` creates
    /// with its final shape (a chunk cannot have a dimension of 0).
    dataset: Option<Dataset>,
    rows_written: usize,
    chunk_rows: usize,
    buffer: Vec<T>,
}

impl<T: H5Type + Copy> Appender<T> {
    /// A dataset of at most `rows` rows (the planned number; a diverged run writes fewer).
    fn new(
        group: &Group,
        name: &str,
        row_shape: &[usize],
        unit: &'static str,
        rows: usize,
    ) -> Self {
        let row = row_shape.iter().product::<usize>();
        Appender {
            group: group.clone(),
            name: name.to_string(),
            unit,
            row_shape: row_shape.to_vec(),
            row,
            dataset: None,
            rows_written: 0,
            chunk_rows: (CHUNK_VALUES / row.max(1)).min(rows).max(1),
            buffer: Vec::new(),
        }
    }

    /// Appends `rows` rows, writing each chunk as it fills.
    fn append(&mut self, rows: usize, values: &[T]) -> hdf5::Result<()> {
        if values.len() != rows * self.row {
            return Err(format!(
                "{}: {} values are not {rows} rows of {}",
                self.name,
                values.len(),
                self.row
            )
            .into());
        }
        if self.row == 0 {
            // Rows of no values only count.
            self.rows_written += rows;
            return Ok(());
        }
        self.buffer.extend_from_slice(values);
        if self.buffer.len() >= self.chunk_rows * self.row {
            self.write_buffer()?;
        }
        Ok(())
    }

    fn write_buffer(&mut self) -> hdf5::Result<()> {
        let rows = self.buffer.len() / self.row;
        let target = match &self.dataset {
            Some(target) => target,
            None => self.dataset.insert(self.create()?),
        };
        let total = self.rows_written + rows;
        let shape: Vec<usize> = std::iter::once(total)
            .chain(self.row_shape.iter().copied())
            .collect();
        target.resize(shape.as_slice())?;
        let block: Vec<usize> = std::iter::once(rows)
            .chain(self.row_shape.iter().copied())
            .collect();
        let view = ArrayView::from_shape(IxDyn(&block), &self.buffer)
            .map_err(|e| hdf5::Error::from(format!("{}: {e}", self.name)))?;
        let selection: Vec<SliceOrIndex> = std::iter::once((self.rows_written..total).into())
            .chain(self.row_shape.iter().map(|_| (..).into()))
            .collect();
        target.write_slice(view, Hyperslab::from(selection))?;
        self.rows_written = total;
        self.buffer.clear();
        Ok(())
    }

    /// The resizable dataset, empty, with its units.
    fn create(&self) -> hdf5::Result<Dataset> {
        let extents = std::iter::once(Extent::resizable(0))
            .chain(self.row_shape.iter().map(|&n| Extent::fixed(n)))
            .collect();
        let mut chunk: Vec<usize> = std::iter::once(self.chunk_rows)
            .chain(self.row_shape.iter().copied())
            .collect();
        let row_bytes = self.row * std::mem::size_of::<T>();
        if row_bytes > MAX_CHUNK_BYTES {
            let parts = row_bytes.div_ceil(MAX_CHUNK_BYTES);
            chunk[1] = chunk[1].div_ceil(parts);
        }
        let created = self
            .group
            .new_dataset::<T>()
            .shape(SimpleExtents::from_vec(extents))
            .chunk(chunk.as_slice())
            .create(self.name.as_str())?;
        attr_str(&created, "units", self.unit)?;
        Ok(created)
    }

    /// Writes what is buffered. A dataset that fits in one chunk was never written: it is
    /// written whole here, contiguous, as a record kept in memory would be.
    fn finish(mut self) -> hdf5::Result<()> {
        if self.dataset.is_some() {
            return match self.buffer.is_empty() {
                true => Ok(()),
                false => self.write_buffer(),
            };
        }
        let rows = self.rows_written + self.buffer.len() / self.row.max(1);
        let shape: Vec<usize> = std::iter::once(rows)
            .chain(self.row_shape.iter().copied())
            .collect();
        dataset(&self.group, &self.name, &self.buffer, &shape, self.unit)
    }
}

/// The sizes a stream's rows have (the dimension, the particles and the grid's DOFs), and how
/// many rows it plans: the history samples and the probes' steps.
#[derive(Clone, Copy, Debug)]
pub struct StreamShape {
    pub dim: usize,
    pub particles: usize,
    pub dofs: usize,
    pub samples: usize,
    pub steps: usize,
}

/// The growing arrays of one run file: per sample the particle states, the grid velocity and
/// the pointwise errors, per step the probes' records (with the wiggle measures of their
/// values so far). The groups `/history`, `/grid`, `/errors` and `/probes/<name>` are created
/// here; the writer adds the rest of their contents.
#[derive(Debug)]
pub struct HistoryStream {
    x: Appender<f64>,
    v: Appender<f64>,
    stress: Appender<f64>,
    density: Appender<f64>,
    grid_v: Appender<f64>,
    volume: Appender<f64>,
    pointwise: [Appender<f64>; 4],
    grid_velocity: Appender<f64>,
    probes: Vec<ProbeStream>,
}

#[derive(Debug)]
struct ProbeStream {
    time: Appender<f64>,
    step: Appender<i64>,
    value: Appender<f64>,
    reference: Appender<f64>,
    tally: WiggleTally,
}

impl HistoryStream {
    /// The groups and (unwritten) datasets in `file`; `probes` gives the probes' names and
    /// quantities (their records may be empty).
    pub fn create(
        file: &hdf5::File,
        shape: StreamShape,
        probe_records: &[ProbeRecord],
    ) -> hdf5::Result<Self> {
        let StreamShape {
            dim: d,
            particles: np,
            dofs: nn,
            samples: nt,
            steps,
        } = shape;
        let history = file.create_group("history")?;
        let grid = file.create_group("grid")?;
        let errors = file.create_group("errors")?;
        let field = |name: &'static str, points: usize| {
            Appender::new(&errors, name, &[points], super::field_unit(name), nt)
        };
        let probe_group = if probe_records.is_empty() {
            None
        } else {
            Some(file.create_group(probes::GROUP)?)
        };
        let probes = match &probe_group {
            None => Vec::new(),
            Some(group) => probe_records
                .iter()
                .map(|probe| ProbeStream::create(group, probe, steps))
                .collect::<hdf5::Result<_>>()?,
        };
        Ok(HistoryStream {
            x: Appender::new(&history, "x", &[np, d], "m", nt),
            v: Appender::new(&history, "v", &[np, d], "m/s", nt),
            stress: Appender::new(&history, "stress", &[np, d, d], "Pa", nt),
            density: Appender::new(&history, "density", &[np], "kg/m^D", nt),
            grid_v: Appender::new(&grid, "v", &[nn, d], "m/s", nt),
            volume: Appender::new(&errors, "volume", &[np], "m^D", nt),
            pointwise: std::array::from_fn(|f| field(ERROR_FIELDS[f], np)),
            grid_velocity: field(GRID_VELOCITY, nn),
            probes,
        })
    }

    /// Appends `samples` samples held in these arrays (Nt x Np x ... values each).
    pub fn append_samples(
        &mut self,
        samples: usize,
        history: &History,
        grid: &GridHistory,
        errors: &Errors,
    ) -> hdf5::Result<()> {
        let n = samples;
        self.x.append(n, &history.x)?;
        self.v.append(n, &history.v)?;
        self.stress.append(n, &history.stress)?;
        self.density.append(n, &history.density)?;
        self.grid_v.append(n, &grid.v)?;
        self.volume.append(n, &errors.volume)?;
        for (appender, values) in self.pointwise.iter_mut().zip(&errors.pointwise) {
            appender.append(n, values)?;
        }
        self.grid_velocity
            .append(n, &errors.grid_velocity.pointwise)
    }

    /// Appends the steps held in these records, in the order of `create`'s.
    pub fn append_probes(&mut self, records: &[ProbeRecord]) -> hdf5::Result<()> {
        for (stream, record) in self.probes.iter_mut().zip(records) {
            let n = record.time.len();
            stream.time.append(n, &record.time)?;
            stream.step.append(n, &record.step)?;
            stream.value.append(n, &record.value)?;
            stream.reference.append(n, &record.reference)?;
            for (&value, &reference) in record.value.iter().zip(&record.reference) {
                stream.tally.push(value, reference);
            }
        }
        Ok(())
    }

    /// Writes what is buffered; returns each probe's wiggle measures over all its steps.
    pub fn finish(self) -> hdf5::Result<Vec<Wiggles>> {
        for appender in [
            self.x,
            self.v,
            self.stress,
            self.density,
            self.grid_v,
            self.volume,
            self.grid_velocity,
        ]
        .into_iter()
        .chain(self.pointwise)
        {
            appender.finish()?;
        }
        self.probes
            .into_iter()
            .map(|probe| {
                probe.time.finish()?;
                probe.step.finish()?;
                probe.value.finish()?;
                probe.reference.finish()?;
                Ok(probe.tally.wiggles())
            })
            .collect()
    }
}

impl ProbeStream {
    /// The probe's group and datasets, of at most `steps` + 1 rows.
    fn create(group: &Group, probe: &ProbeRecord, steps: usize) -> hdf5::Result<Self> {
        let g = group.create_group(&probe.name)?;
        let rows = steps + 1;
        Ok(ProbeStream {
            time: Appender::new(&g, probes::TIME, &[], "s", rows),
            step: Appender::new(&g, probes::STEP, &[], "1", rows),
            value: Appender::new(&g, probes::VALUE, &[], probe.unit(), rows),
            reference: Appender::new(&g, probes::REFERENCE, &[], probe.unit(), rows),
            tally: WiggleTally::default(),
        })
    }
}
