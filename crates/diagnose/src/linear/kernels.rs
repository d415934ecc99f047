//! The vector kernels of the sums over poses: element by element, or as
//! four interleaved partial sums, with no fused multiply-add, so that the
//! bits are the same at any vector width ([`pulp`]).

/// `out += w x`, element by element.
#[inline(always)]
pub(super) fn axpy<S: pulp::Simd>(simd: S, out: &mut [f64], x: &[f64], w: f64) {
    let len = out.len().min(x.len());
    let (oh, ot) = S::as_mut_simd_f64s(&mut out[..len]);
    let (xh, xt) = S::as_simd_f64s(&x[..len]);
    let wv = simd.splat_f64s(w);
    for (o, x) in oh.iter_mut().zip(xh) {
        *o = simd.add_f64s(*o, simd.mul_f64s(*x, wv));
    }
    for (o, x) in ot.iter_mut().zip(xt) {
        *o += x * w;
    }
}

/// The four lanes of a four-wide vector.
#[inline(always)]
fn lanes<S: pulp::Simd>(v: S::f64s) -> [f64; 4] {
    let mut out = [0.0; 4];
    if let Some(o) = S::as_mut_simd_f64s(&mut out).0.first_mut() {
        *o = v;
    }
    out
}

/// `(s0 + s1) + (s2 + s3) + tail` of four partial sums.
#[inline(always)]
fn combine(s: [f64; 4], tail: f64) -> f64 {
    (s[0] + s[1]) + (s[2] + s[3]) + tail
}

/// `n` products of slices, summed as the scan's scalar kernels do (element
/// `t` into partial sum `t mod 4`, the tail after the last whole four in
/// order, then [`combine`]) with four-wide vectors when `S` has four lanes
/// and with the scalar kernel otherwise: the same bits either way (no
/// fused multiply-add).
#[inline(always)]
pub(super) fn sums4<S: pulp::Simd, const N: usize, const M: usize>(
    simd: S,
    x: [&[f64]; M],
    vector: impl Fn(&[S::f64s; M]) -> [S::f64s; N],
    scalar: impl Fn(&[f64; M]) -> [f64; N],
) -> [f64; N] {
    let len = x.iter().map(|v| v.len()).min().unwrap_or(0);
    let whole = len / 4 * 4;
    let mut partial = [[0.0; 4]; N];
    if S::F64_LANES == 4 {
        let heads = x.map(|v| S::as_simd_f64s(&v[..whole]).0);
        let mut acc = [simd.splat_f64s(0.0); N];
        for i in 0..whole / 4 {
            let t = vector(&std::array::from_fn(|m| heads[m][i]));
            for q in 0..N {
                acc[q] = simd.add_f64s(acc[q], t[q]);
            }
        }
        for q in 0..N {
            partial[q] = lanes::<S>(acc[q]);
        }
    } else {
        for i in (0..whole).step_by(4) {
            for l in 0..4 {
                let t = scalar(&std::array::from_fn(|m| x[m][i + l]));
                for q in 0..N {
                    partial[q][l] += t[q];
                }
            }
        }
    }
    let mut tail = [0.0; N];
    for i in whole..len {
        let t = scalar(&std::array::from_fn(|m| x[m][i]));
        for q in 0..N {
            tail[q] += t[q];
        }
    }
    std::array::from_fn(|q| combine(partial[q], tail[q]))
}

/// `a . b` of 3-vectors.
pub(super) fn dot3(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
