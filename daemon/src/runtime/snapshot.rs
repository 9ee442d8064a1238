//! Lock-free "latest value" exchange (a triple buffer) for `Copy` data such as the status.
//!
//! The control thread writes a status snapshot without waiting; the service thread reads the
//! newest complete one. Neither side ever blocks the other.

use std::cell::UnsafeCell;
use std::sync::Arc;
use std::sync::atomic::{AtomicU8, Ordering};

/// Set in `middle` when the middle slot holds a value the reader has not seen.
const FRESH: u8 = 0b100;
const INDEX: u8 = 0b011;

struct Buffers<T> {
    slots: [UnsafeCell<T>; 3],
    /// Index of the slot between writer and reader, plus [`FRESH`].
    middle: AtomicU8,
}

// SAFETY: at any time each slot is owned by exactly one of writer, reader or `middle`; slots
// change hands only through the atomic swap on `middle`.
unsafe impl<T: Send> Sync for Buffers<T> {}

/// The writing end; exactly one exists.
pub struct SnapshotWriter<T> {
    buffers: Arc<Buffers<T>>,
    slot: u8,
}

/// The reading end; exactly one exists.
pub struct SnapshotReader<T> {
    buffers: Arc<Buffers<T>>,
    slot: u8,
}

/// Creates a connected writer and reader, both starting from `initial`.
pub fn snapshot<T: Copy + Send>(initial: T) -> (SnapshotWriter<T>, SnapshotReader<T>) {
    let buffers = Arc::new(Buffers {
        slots: [
            UnsafeCell::new(initial),
            UnsafeCell::new(initial),
            UnsafeCell::new(initial),
        ],
        middle: AtomicU8::new(1),
    });
    (
        SnapshotWriter {
            buffers: Arc::clone(&buffers),
            slot: 0,
        },
        SnapshotReader { buffers, slot: 2 },
    )
}

impl<T: Copy> SnapshotWriter<T> {
    /// Publishes `value` as the newest snapshot. Wait-free, no allocation.
    pub fn write(&mut self, value: &T) {
        // SAFETY: the writer exclusively owns `self.slot` until it swaps it into `middle`.
        unsafe { *self.buffers.slots[self.slot as usize].get() = *value };
        let previous = self
            .buffers
            .middle
            .swap(self.slot | FRESH, Ordering::AcqRel);
        self.slot = previous & INDEX;
    }
}

impl<T: Copy> SnapshotReader<T> {
    /// The newest snapshot written (the same one again if nothing new was written).
    pub fn read(&mut self) -> T {
        if self.buffers.middle.load(Ordering::Acquire) & FRESH != 0 {
            let previous = self.buffers.middle.swap(self.slot, Ordering::AcqRel);
            self.slot = previous & INDEX;
        }
        // SAFETY: the reader exclusively owns `self.slot`.
        unsafe { *self.buffers.slots[self.slot as usize].get() }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reader_sees_the_newest_value() {
        let (mut writer, mut reader) = snapshot(0u64);
        assert_eq!(reader.read(), 0);
        writer.write(&1);
        writer.write(&2);
        assert_eq!(reader.read(), 2);
        assert_eq!(reader.read(), 2);
        writer.write(&3);
        assert_eq!(reader.read(), 3);
    }

    #[test]
    fn values_are_never_torn_across_threads() {
        let (mut writer, mut reader) = snapshot([0u64; 16]);
        let producer = std::thread::spawn(move || {
            for i in 1..=20_000u64 {
                writer.write(&[i; 16]);
            }
        });
        let mut last = 0;
        while last < 20_000 {
            let value = reader.read();
            assert!(
                value.iter().all(|&v| v == value[0]),
                "torn snapshot {value:?}"
            );
            assert!(value[0] >= last, "went back in time");
            last = value[0];
        }
        producer.join().unwrap();
    }
}
