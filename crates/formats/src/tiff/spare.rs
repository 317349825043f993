//! Page buffers handed back for reuse. A series analysis decodes every page twice (its two
//! passes) and drops each plane right after use; a page decoded into a fresh `Vec` costs an
//! allocation the size of the page, which the allocator often takes from the system again and the
//! decoder fills with zeros before it writes the pixels (on 1024² pages about a tenth of the
//! analysis' CPU time). A caller that is done with a plane's codes gives them back with
//! [`give_back`]; the next 16-bit page of the same size decoded on that thread is written over
//! them (every byte of it is overwritten).
//!
//! At most [`KEEP`] buffers per thread are kept, so the memory held is bounded by that many pages.

use std::cell::RefCell;

/// Buffers kept per thread.
pub const KEEP: usize = 2;

thread_local! {
    static SPARE: RefCell<Vec<Vec<u16>>> = const { RefCell::new(Vec::new()) };
}

/// Hand back the codes of a plane the caller is done with; the oldest kept buffer is dropped when
/// [`KEEP`] are held already.
pub fn give_back(codes: Vec<u16>) {
    if codes.is_empty() {
        return;
    }
    SPARE.with(|spare| {
        let mut spare = spare.borrow_mut();
        if spare.len() >= KEEP {
            spare.remove(0);
        }
        spare.push(codes);
    });
}

/// A kept buffer of exactly `len` codes, if this thread holds one.
pub(crate) fn take(len: usize) -> Option<Vec<u16>> {
    SPARE.with(|spare| {
        let mut spare = spare.borrow_mut();
        let at = spare.iter().position(|v| v.len() == len)?;
        Some(spare.swap_remove(at))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn buffers_come_back_by_size_and_at_most_keep_are_held() {
        give_back(vec![1; 10]);
        give_back(vec![2; 20]);
        give_back(vec![3; 10]);
        // The first (10) was dropped for the third.
        assert_eq!(take(20), Some(vec![2; 20]));
        assert_eq!(take(10), Some(vec![3; 10]));
        assert_eq!(take(10), None);
        give_back(Vec::new());
        assert_eq!(take(0), None);
    }
}
