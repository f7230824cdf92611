//! Allocations whose size the input sets. Where `vec![value; n]` would abort the process when
//! the system refuses the memory, `filled` panics with the size and what it was for, which the
//! runner catches and records as the run's failure, so the other runs go on.

/// `n` copies of `value`, for `what` (named in the message if the memory is refused).
pub fn filled<T: Clone>(n: usize, value: T, what: &str) -> Vec<T> {
    let mut values = Vec::new();
    if values.try_reserve_exact(n).is_err() {
        panic!(
            "could not allocate {n} values of {} bytes for {what}",
            std::mem::size_of::<T>()
        );
    }
    values.resize(n, value);
    values
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_refused_allocation_panics_with_its_size_and_purpose() {
        assert_eq!(filled(3, 1.5, "x"), vec![1.5; 3]);
        let refused = std::panic::catch_unwind(|| filled(usize::MAX / 8, 0.0f64, "the stencils"));
        let payload = refused.unwrap_err();
        let message = payload.downcast_ref::<String>().unwrap();
        assert!(message.contains("for the stencils"), "{message}");
    }
}
