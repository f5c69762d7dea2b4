//! Golden-section search for the minimum of a function on an interval, shared by the posture
//! refinement, the ball end mill's lowest point and the dexel sweep's deepest point (each
//! unimodal on its bracket).

/// The golden ratio's conjugate: each iteration keeps this fraction of the bracket.
const R: f64 = 0.618_033_988_749_894_9;

/// Minimises `key(eval(x))` over `[a, b]` in `iterations` golden-section steps (the bracket
/// shrinks to `0.618^iterations` of its width) and returns the better of the last two
/// evaluations (the left one on a tie). `eval` may fail softly: give such points an infinite
/// key.
pub(crate) fn minimise<T>(
    mut a: f64,
    mut b: f64,
    iterations: usize,
    mut eval: impl FnMut(f64) -> T,
    key: impl Fn(&T) -> f64,
) -> T {
    let mut c = b - R * (b - a);
    let mut d = a + R * (b - a);
    let (mut pc, mut pd) = (eval(c), eval(d));
    for _ in 0..iterations {
        if key(&pc) < key(&pd) {
            b = d;
            d = c;
            pd = pc;
            c = b - R * (b - a);
            pc = eval(c);
        } else {
            a = c;
            c = d;
            pc = pd;
            d = a + R * (b - a);
            pd = eval(d);
        }
    }
    if key(&pc) < key(&pd) { pc } else { pd }
}
