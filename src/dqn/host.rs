//! Reading CPU tensors in place: the hot loop reads a few dozen floats per update, and
//! `to_vec` would allocate a copy each time.

use candle_core::{bail, Result, Storage, Tensor};

/// Calls `f` with the tensor's `f32` values in row-major order.
pub(crate) fn with_f32<R>(t: &Tensor, f: impl FnOnce(&[f32]) -> R) -> Result<R> {
    if !t.is_contiguous() {
        return with_f32(&t.contiguous()?, f);
    }
    let (storage, layout) = t.storage_and_layout();
    let Storage::Cpu(cpu) = &*storage else {
        bail!("only CPU tensors can be read in place")
    };
    let data = cpu.as_slice::<f32>()?;
    let start = layout.start_offset();
    Ok(f(&data[start..start + layout.shape().elem_count()]))
}
