//! Lock-free single-slot handoff of boxed values between two threads.
//!
//! The control thread must not allocate, free or lock. Sequences are boxed by the service
//! thread, handed in through one slot, and the sequences the controller gives back are handed
//! out through another slot so that the service thread frees them.

use std::ptr;
use std::sync::atomic::{AtomicPtr, Ordering};

/// A slot holding at most one `Box<T>`; `put` and `take` are single atomic operations.
pub struct Slot<T> {
    value: AtomicPtr<T>,
}

// SAFETY: the slot transfers ownership of a `Box<T>` between threads; that is sound when `T`
// may be sent between threads.
unsafe impl<T: Send> Send for Slot<T> {}
// SAFETY: all access to the pointer goes through atomic swaps, so exactly one side owns it.
unsafe impl<T: Send> Sync for Slot<T> {}

impl<T> Slot<T> {
    /// An empty slot.
    pub fn new() -> Self {
        Self {
            value: AtomicPtr::new(ptr::null_mut()),
        }
    }

    /// Stores `value` if the slot is empty; gives it back if it is full.
    pub fn put(&self, value: Box<T>) -> Result<(), Box<T>> {
        let raw = Box::into_raw(value);
        match self
            .value
            .compare_exchange(ptr::null_mut(), raw, Ordering::AcqRel, Ordering::Acquire)
        {
            Ok(_) => Ok(()),
            // SAFETY: `raw` came from `Box::into_raw` above and was not stored.
            Err(_) => Err(unsafe { Box::from_raw(raw) }),
        }
    }

    /// Removes and returns the stored value, if any. Never allocates or frees.
    pub fn take(&self) -> Option<Box<T>> {
        let raw = self.value.swap(ptr::null_mut(), Ordering::AcqRel);
        // SAFETY: a non-null pointer in the slot always comes from `Box::into_raw` in `put`, and
        // the swap made this call its only owner.
        (!raw.is_null()).then(|| unsafe { Box::from_raw(raw) })
    }
}

impl<T> Default for Slot<T> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T> Drop for Slot<T> {
    fn drop(&mut self) {
        drop(self.take());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;

    #[test]
    fn holds_one_value_at_a_time() {
        let slot = Slot::new();
        assert!(slot.take().is_none());
        slot.put(Box::new(1)).unwrap();
        assert_eq!(*slot.put(Box::new(2)).unwrap_err(), 2);
        assert_eq!(*slot.take().unwrap(), 1);
        assert!(slot.take().is_none());
    }

    #[test]
    fn moves_every_value_exactly_once_between_threads() {
        let slot = Arc::new(Slot::new());
        let consumer = {
            let slot = Arc::clone(&slot);
            std::thread::spawn(move || {
                let mut sum = 0u64;
                let mut received = 0;
                while received < 1000 {
                    if let Some(value) = slot.take() {
                        sum += *value;
                        received += 1;
                    }
                }
                sum
            })
        };
        for i in 0..1000u64 {
            let mut value = Box::new(i);
            while let Err(back) = slot.put(value) {
                value = back;
                std::hint::spin_loop();
            }
        }
        assert_eq!(consumer.join().unwrap(), (0..1000u64).sum::<u64>());
    }
}
