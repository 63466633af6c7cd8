//! A place for a value built at run time that must live for `'static` (task arguments), with
//! no heap: each slot can be filled once.

use core::cell::UnsafeCell;
use core::mem::MaybeUninit;
use core::sync::atomic::{AtomicBool, Ordering};

/// Storage for one `T`, filled at most once.
pub struct Slot<T> {
    taken: AtomicBool,
    value: UnsafeCell<MaybeUninit<T>>,
}

// SAFETY: `put` hands out the only reference to the value, exactly once (guarded by `taken`);
// the value is shared across tasks only through that `&'static mut T`, and only if `T: Send`.
unsafe impl<T: Send> Sync for Slot<T> {}

impl<T> Default for Slot<T> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T> Slot<T> {
    /// An empty slot.
    pub const fn new() -> Self {
        Self {
            taken: AtomicBool::new(false),
            value: UnsafeCell::new(MaybeUninit::uninit()),
        }
    }

    /// Moves `value` in and returns it for good; `None` (and `value` dropped) if the slot was
    /// already filled.
    // A `&'static mut` from `&'static self` is sound here: the `taken` flag lets it happen once.
    #[allow(clippy::mut_from_ref)]
    pub fn put(&'static self, value: T) -> Option<&'static mut T> {
        if self.taken.swap(true, Ordering::AcqRel) {
            return None;
        }
        // SAFETY: the swap above makes this the only access to `value`, ever.
        Some(unsafe { (*self.value.get()).write(value) })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fills_once() {
        static S: Slot<u32> = Slot::new();
        let v = S.put(5).unwrap();
        *v += 1;
        assert_eq!(*v, 6);
        assert!(S.put(7).is_none());
    }
}
