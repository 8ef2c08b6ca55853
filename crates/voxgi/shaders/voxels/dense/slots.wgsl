// The slot pool, one part per window: window w of the volume's stacked cubes owns slots
// [w·C, (w + 1)·C), C = `window_slots()` (one window, the dense volume's: the whole pool), so
// that a clipmap can rebuild one level while the others keep their slots and their light. Its
// words in the volume's counters (`counters`, array<atomic<u32>>, and `slot_voxel`, declared
// by the includer), from WINDOW_WORDS, per window: the slots it asked for (counted past C),
// those before its last build (cleared by the next), its static geometry's (below them the
// build's, above them the last update's), and those its last build kept from before a move
// (the first of its part: dense_build's `keep` takes them before any other). `DenseVolume`'s
// counters layout is the twin.

const WINDOW_WORDS: u32 = 18u;
const MAX_WINDOWS: u32 = 8u;
const WINDOW_STRIDE: u32 = 4u;
const W_COUNT: u32 = 0u;
const W_PREVIOUS: u32 = 1u;
const W_STATIC: u32 = 2u;
const W_KEPT: u32 = 3u;

fn window_word(w: u32, k: u32) -> u32 {
    return WINDOW_WORDS + w * WINDOW_STRIDE + k;
}

// Slots of a window's part.
fn window_slots(windows: u32) -> u32 {
    return arrayLength(&slot_voxel) / windows;
}

// Slots window `w` holds (at most its part).
fn window_filled(w: u32, windows: u32) -> u32 {
    return min(atomicLoad(&counters[window_word(w, W_COUNT)]), window_slots(windows));
}

// Slot `s` holds a leaf.
fn slot_filled(s: u32, windows: u32) -> bool {
    let c = window_slots(windows);
    let w = s / c;
    return w < windows && s - w * c < window_filled(w, windows);
}

// Slot `s` holds a leaf of the static geometry.
fn slot_static(s: u32, windows: u32) -> bool {
    let c = window_slots(windows);
    let w = s / c;
    return w < windows && s - w * c < atomicLoad(&counters[window_word(w, W_STATIC)]);
}

// The slot of the t-th filled slot, through the windows' parts in turn (leaving out their
// free slots: a dispatch over the parts' whole length would run threads for nothing), or
// 0xffffffff past the last.
fn filled_slot(t: u32, windows: u32) -> u32 {
    let c = window_slots(windows);
    var first = 0u;
    for (var w = 0u; w < windows; w++) {
        let n = window_filled(w, windows);
        if t < first + n {
            return w * c + t - first;
        }
        first += n;
    }
    return 0xffffffffu;
}
