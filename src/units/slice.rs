//! `get` and `get_mut` for `const fn`s, where the slice methods of those names cannot be
//! called (their index is a trait): the element at an index, or `None` out of range, without
//! the panic of `s[i]` (coding standard, R3).

/// The element at `i`, or `None` when `i` is out of range.
pub(crate) const fn get<T>(s: &[T], i: usize) -> Option<&T> {
    match s.split_at_checked(i) {
        Some((_, rest)) => rest.first(),
        None => None,
    }
}

/// The element at `i`, mutably, or `None` when `i` is out of range.
pub(crate) const fn get_mut<T>(s: &mut [T], i: usize) -> Option<&mut T> {
    match s.split_at_mut_checked(i) {
        Some((_, rest)) => rest.first_mut(),
        None => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn in_range_and_out() {
        let mut a = [10, 20, 30];
        assert_eq!(get(&a, 0), Some(&10));
        assert_eq!(get(&a, 2), Some(&30));
        assert_eq!(get(&a, 3), None);
        assert_eq!(get(&a, usize::MAX), None);
        if let Some(x) = get_mut(&mut a, 1) {
            *x = 21;
        }
        assert_eq!(a, [10, 21, 30]);
        assert_eq!(get_mut(&mut a, 3), None);
        assert_eq!(get::<u8>(&[], 0), None);
    }
}
