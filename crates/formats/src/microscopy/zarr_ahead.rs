//! Which planes of an OME-Zarr series on a server to fetch ahead (`crate::remote`'s
//! `RemoteStore::fetch_ahead`): a reader going through a series in order along one axis (the
//! loads along `t` or `z`, the channels along `c`) reads plane after plane, each its own chunks
//! and each a round trip away; naming the next [`PLANES_AHEAD`] planes' chunks when a plane is
//! read lets them come at the same time. The order is told from the planes read lately in the
//! same series (by any reader of the process): a plane whose predecessor along one axis was
//! among them is read in order along that axis (the analysis' threads each go through their
//! own part of the series, so several such runs interleave). A plane read out of order (the
//! first of a run) names none.

use std::collections::HashMap;
use std::sync::{Mutex, OnceLock};

use super::{Axes, PlaneIndex};

/// Planes named ahead of the one read.
pub(super) const PLANES_AHEAD: usize = 6;

/// Planes remembered per series.
const REMEMBERED: usize = 32;

/// The planes read lately of each (store, series), the latest last.
type Recent = HashMap<(String, usize), Vec<PlaneIndex>>;

fn recent() -> &'static Mutex<Recent> {
    static RECENT: OnceLock<Mutex<Recent>> = OnceLock::new();
    RECENT.get_or_init(Default::default)
}

/// Record that `index` of series `series` of the store `store` is read, and return the planes
/// to fetch ahead of it (module docs).
pub(super) fn note_read(
    store: &str,
    series: usize,
    index: &PlaneIndex,
    axes: &Axes,
) -> Vec<PlaneIndex> {
    let mut all = recent().lock().unwrap_or_else(|e| e.into_inner());
    let read = all.entry((store.to_string(), series)).or_default();
    let next = ahead_of(read, index, axes);
    read.retain(|i| i != index);
    read.push(index.clone());
    if read.len() > REMEMBERED {
        read.remove(0);
    }
    next
}

/// The next [`PLANES_AHEAD`] planes after `index` along the first axis (t, z, c) whose plane
/// before `index` is in `read`, within the axis' size; none when there is no such axis.
pub(super) fn ahead_of(read: &[PlaneIndex], index: &PlaneIndex, axes: &Axes) -> Vec<PlaneIndex> {
    let step = |axis: usize, by: isize| {
        let mut i = index.clone();
        let at = match axis {
            0 => &mut i.t,
            1 => &mut i.z,
            _ => &mut i.c,
        };
        *at = at.checked_add_signed(by)?;
        Some(i)
    };
    let sizes = [axes.t, axes.z, axes.c];
    let Some(axis) = (0..3).find(|&a| step(a, -1).is_some_and(|before| read.contains(&before)))
    else {
        return Vec::new();
    };
    // Planes already read (another thread's run reached them first) are not fetched again.
    (1..=PLANES_AHEAD as isize)
        .filter_map(|k| step(axis, k))
        .filter(|i| [i.t, i.z, i.c][axis] < sizes[axis] && !read.contains(i))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn axes(t: usize, z: usize, c: usize) -> Axes {
        Axes {
            t,
            z,
            c,
            y: 8,
            x: 8,
            extra: Default::default(),
        }
    }

    #[test]
    fn planes_read_in_order_name_the_next_ones_along_their_axis() {
        let a = axes(40, 3, 2);
        let ts = |v: &[PlaneIndex]| v.iter().map(|i| i.t).collect::<Vec<_>>();
        let read = [PlaneIndex::tzc(4, 1, 0)];
        let next = ahead_of(&read, &PlaneIndex::tzc(5, 1, 0), &a);
        assert_eq!(ts(&next), (6..6 + PLANES_AHEAD).collect::<Vec<_>>());
        assert!(next.iter().all(|i| i.z == 1 && i.c == 0));
        // Two runs interleaved (two threads, each its half of the series): each in order.
        let read = [PlaneIndex::tzc(0, 0, 0), PlaneIndex::tzc(20, 0, 0)];
        assert_eq!(ts(&ahead_of(&read, &PlaneIndex::tzc(1, 0, 0), &a))[0], 2);
        assert_eq!(ts(&ahead_of(&read, &PlaneIndex::tzc(21, 0, 0), &a))[0], 22);
        // Not past the axis' end.
        let read = [PlaneIndex::tzc(37, 0, 0), PlaneIndex::tzc(38, 0, 0)];
        assert_eq!(ts(&ahead_of(&read, &PlaneIndex::tzc(38, 0, 0), &a)), [39]);
        assert!(ahead_of(&read, &PlaneIndex::tzc(39, 0, 0), &a).len() <= 1);
        // Along z.
        let read = [PlaneIndex::tzc(7, 0, 1)];
        let next = ahead_of(&read, &PlaneIndex::tzc(7, 1, 1), &a);
        assert_eq!(next, vec![PlaneIndex::tzc(7, 2, 1)]);
        // Planes already read are not named again.
        let read = [PlaneIndex::tzc(0, 0, 0), PlaneIndex::tzc(20, 0, 0)];
        let next = ts(&ahead_of(&read, &PlaneIndex::tzc(16, 0, 0), &a));
        assert!(next.is_empty());
        let read = [PlaneIndex::tzc(15, 0, 0), PlaneIndex::tzc(20, 0, 0)];
        assert_eq!(
            ts(&ahead_of(&read, &PlaneIndex::tzc(16, 0, 0), &a)),
            [17, 18, 19, 21, 22]
        );
        // Out of order: a jump, a plane of another channel, nothing read before.
        let read = [PlaneIndex::tzc(1, 0, 0)];
        assert!(ahead_of(&read, &PlaneIndex::tzc(9, 0, 0), &a).is_empty());
        assert!(ahead_of(&read, &PlaneIndex::tzc(2, 1, 0), &a).is_empty());
        assert!(ahead_of(&[], &PlaneIndex::tzc(2, 0, 0), &a).is_empty());
    }

    #[test]
    fn the_first_plane_of_a_series_names_none_and_the_second_does() {
        let a = axes(10, 1, 1);
        let store = "s3://b/first.zarr";
        assert!(note_read(store, 0, &PlaneIndex::tzc(0, 0, 0), &a).is_empty());
        assert_eq!(
            note_read(store, 0, &PlaneIndex::tzc(1, 0, 0), &a).len(),
            PLANES_AHEAD
        );
        // Another series of the same store keeps its own order.
        assert!(note_read(store, 1, &PlaneIndex::tzc(2, 0, 0), &a).is_empty());
    }
}
