//! Images between hikari and numpy.

use hikari_core::render::Image;
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray3, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// `image` as a float32 array of shape (height, width, 3): one copy (its
/// pixels into a flat vector), which numpy then owns.
pub fn image_to_array<'py>(py: Python<'py>, image: &Image) -> PyResult<Bound<'py, PyAny>> {
    let flat: Vec<f32> = image.pixels.iter().flat_map(|p| p.to_array()).collect();
    let array = PyArray1::from_vec(py, flat);
    Ok(array.reshape([image.height as usize, image.width as usize, 3])?.into_any())
}

/// A depth image as a float32 array of shape (height, width).
pub fn depth_to_array<'py>(py: Python<'py>, depth: &[f32], width: u32, height: u32) -> PyResult<Bound<'py, PyAny>> {
    let array = PyArray1::from_slice(py, depth);
    Ok(array.reshape([height as usize, width as usize])?.into_any())
}

/// An array of shape (height, width, 3) as an image.
pub fn image_from_array(array: &PyReadonlyArray3<'_, f32>) -> PyResult<Image> {
    let shape = array.shape();
    let (h, w, c) = (shape[0], shape[1], shape[2]);
    if c != 3 || h == 0 || w == 0 || h > u32::MAX as usize || w > u32::MAX as usize {
        return Err(PyValueError::new_err(format!("an image is (height, width, 3) float32; got shape {shape:?}")));
    }
    let view = array.as_array();
    let mut image = Image::new(w as u32, h as u32);
    for (i, pixel) in image.pixels.iter_mut().enumerate() {
        let (y, x) = (i / w, i % w);
        *pixel = glam::Vec3::new(view[[y, x, 0]], view[[y, x, 1]], view[[y, x, 2]]);
    }
    Ok(image)
}
