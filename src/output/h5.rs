//! The typed HDF5 reads and writes every group of the layout is made of: scalar attributes,
//! string datasets, and datasets with their `units` attribute, read back with errors that
//! name the object as h5dump writes its path.

use hdf5::types::VarLenUnicode;
use hdf5::{Attribute, Dataset, Group, H5Type, Location};
use ndarray::{ArrayView, IxDyn};

fn shape_error(e: ndarray::ShapeError) -> hdf5::Error {
    hdf5::Error::from(format!("array shape: {e}"))
}

/// A dataset of `shape` (row-major `data`) with its `units` attribute.
pub(super) fn dataset<T: H5Type>(
    group: &Group,
    name: &str,
    data: &[T],
    shape: &[usize],
    unit: &str,
) -> hdf5::Result<()> {
    let view = ArrayView::from_shape(IxDyn(shape), data).map_err(shape_error)?;
    let ds = group.new_dataset_builder().with_data(view).create(name)?;
    attr_str(&ds, "units", unit)
}

pub(super) fn string_dataset(group: &Group, name: &str, value: &str) -> hdf5::Result<()> {
    group
        .new_dataset::<VarLenUnicode>()
        .shape(())
        .create(name)?
        .write_scalar(&to_unicode(name, value)?)
}

fn to_unicode(name: &str, value: &str) -> hdf5::Result<VarLenUnicode> {
    value
        .parse()
        .map_err(|e| hdf5::Error::from(format!("{name}: {e}")))
}

pub(super) fn attr_str(loc: &Location, name: &str, value: &str) -> hdf5::Result<()> {
    loc.new_attr::<VarLenUnicode>()
        .shape(())
        .create(name)?
        .write_scalar(&to_unicode(name, value)?)
}

pub(super) fn attr_f64(loc: &Location, name: &str, value: f64) -> hdf5::Result<()> {
    loc.new_attr::<f64>()
        .shape(())
        .create(name)?
        .write_scalar(&value)
}

pub(super) fn attr_i64(loc: &Location, name: &str, value: i64) -> hdf5::Result<()> {
    loc.new_attr::<i64>()
        .shape(())
        .create(name)?
        .write_scalar(&value)
}

/// Where `name` lies below `group`, as h5dump writes it: `/history/x`.
pub(super) fn path_in(group: &Group, name: &str) -> String {
    format!("{}/{name}", group.name().trim_end_matches('/'))
}

/// The group `name` of `parent` (a path below it).
pub(super) fn group(parent: &Group, name: &str) -> hdf5::Result<Group> {
    if !parent.link_exists(name) {
        return Err(format!("lacks {}", path_in(parent, name)).into());
    }
    parent
        .group(name)
        .map_err(|_| format!("{} is not a group", path_in(parent, name)).into())
}

/// The dataset `name` of `group` (a path below it, such as `history/x`).
pub(super) fn open_dataset(group: &Group, name: &str) -> hdf5::Result<Dataset> {
    if !group.link_exists(name) {
        return Err(format!("lacks {}", path_in(group, name)).into());
    }
    group
        .dataset(name)
        .map_err(|_| format!("{} is not a dataset", path_in(group, name)).into())
}

/// A dataset of the shape `expected`, where `None` takes any length on its axis: what a
/// slice of it needs, and what keeps the arrays of one run the same length.
pub(super) fn shaped(
    group: &Group,
    name: &str,
    expected: &[Option<usize>],
) -> hdf5::Result<Dataset> {
    let ds = open_dataset(group, name)?;
    let shape = ds.shape();
    let path = path_in(group, name);
    if shape.len() != expected.len() {
        return Err(format!(
            "dataset {path} has {} dimensions, {} expected",
            shape.len(),
            expected.len()
        )
        .into());
    }
    if shape
        .iter()
        .zip(expected)
        .any(|(&n, e)| e.is_some_and(|e| e != n))
    {
        let text = |axes: Vec<String>| format!("({})", axes.join(", "));
        let want = expected
            .iter()
            .map(|e| e.map_or("any".into(), |n| n.to_string()));
        return Err(format!(
            "dataset {path} has shape {}, {} expected",
            text(shape.iter().map(usize::to_string).collect()),
            text(want.collect())
        )
        .into());
    }
    Ok(ds)
}

/// The attribute `name` of `loc`, said in errors as `the attribute 'name'` (of the root) or
/// `the attribute 'name' of /errors/norms`.
fn attr_words(loc: &Location, name: &str) -> String {
    match loc.name().as_str() {
        "/" => format!("the attribute '{name}'"),
        place => format!("the attribute '{name}' of {place}"),
    }
}

pub(super) fn open_attr(loc: &Location, name: &str) -> hdf5::Result<Attribute> {
    loc.attr(name)
        .map_err(|_| format!("lacks {}", attr_words(loc, name)).into())
}

/// A scalar attribute read as `T`, which names `kind` in its error.
fn scalar<T: hdf5::H5Type>(loc: &Location, name: &str, kind: &str) -> hdf5::Result<T> {
    let attr = open_attr(loc, name)?;
    if !attr.is_scalar() {
        return Err(format!("{} is not a single value", attr_words(loc, name)).into());
    }
    attr.read_scalar::<T>()
        .map_err(|_| format!("{} is not {kind}", attr_words(loc, name)).into())
}

pub(super) fn read_str(loc: &Location, name: &str) -> hdf5::Result<String> {
    Ok(scalar::<VarLenUnicode>(loc, name, "a string")?.to_string())
}

pub(super) fn read_f64(loc: &Location, name: &str) -> hdf5::Result<f64> {
    scalar(loc, name, "a number")
}

pub(super) fn read_i64(loc: &Location, name: &str) -> hdf5::Result<i64> {
    scalar(loc, name, "an integer")
}
