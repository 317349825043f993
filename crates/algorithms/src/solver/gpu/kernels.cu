// The GPU side of the load-controlled solver (crates/algorithms/src/solver/cg/load): the
// elastic operator's set-up and its pad/multiply/crop passes around cuFFT, and the fused passes
// of one conjugate-gradient iteration. Each pass mirrors the host pass of the same name in
// cg/load/passes.rs pixel for pixel; only the order of the sums differs.
//
// Reductions are deterministic: every reducing kernel runs on a fixed grid of BLOCKS blocks of
// THREADS threads (set by the host), each thread folds a fixed grid-stride set of pixels, each
// block folds its threads in a fixed tree, and the host folds the block partials in block order.
// The result does not depend on scheduling, so a solve repeats bit for bit on one device.
//
// Compiled at run time by NVRTC (no headers: only built-in functions are used).

#define THREADS 256

#define OP_SUM 0
#define OP_MIN 1
#define OP_MAX 2

#define INF __longlong_as_double(0x7ff0000000000000LL)

// Plasticity modes: 0 elastic (no bound), 1 penetration hardness (bound = cap),
// 2 hardening (bound = p_Y of the previous load, compliance = 1/k).
struct Plastic {
    int mode;
    double compliance;
    const double* bound;
};

__device__ __forceinline__ double cap_of(const Plastic& pl, long long i) {
    return pl.mode == 1 ? pl.bound[i] : INF;
}

__device__ __forceinline__ double spring_of(const Plastic& pl, long long i, double p) {
    return pl.mode == 2 ? fmax(p - pl.bound[i], 0.0) * pl.compliance : 0.0;
}

__device__ __forceinline__ double spring_energy_of(const Plastic& pl, long long i, double p) {
    if (pl.mode != 2) return 0.0;
    double over = fmax(p - pl.bound[i], 0.0);
    return 0.5 * over * over * pl.compliance;
}

__device__ __forceinline__ double spring_compliance_of(const Plastic& pl, long long i, double p) {
    return (pl.mode == 2 && p > pl.bound[i]) ? pl.compliance : 0.0;
}

// The effective gap e − delta = s + u + spring − delta at pixel i for pressure p.
__device__ __forceinline__ double gap_of(const Plastic& pl, const double* s, const double* u,
                                         long long i, double p, double delta) {
    return s[i] + u[i] + spring_of(pl, i, p) - delta;
}

// Rust's f64::clamp(lo, hi) for lo <= hi.
__device__ __forceinline__ double clamp_to(double x, double lo, double hi) {
    return x < lo ? lo : (x > hi ? hi : x);
}

// Rust's f64::min / f64::max (the non-NaN operand when one is NaN), as fmin / fmax.
__device__ __forceinline__ double combine(int op, double a, double b) {
    return op == OP_SUM ? a + b : (op == OP_MIN ? fmin(a, b) : fmax(a, b));
}

// Fold K per-thread values over the block in a fixed tree; thread 0 writes the block's K
// partials to out[blockIdx.x * K + k].
template <int K>
__device__ void block_reduce(double* v, const int* ops, double* out) {
    __shared__ double sh[K * THREADS];
    const int tid = threadIdx.x;
    for (int k = 0; k < K; ++k) sh[k * THREADS + tid] = v[k];
    __syncthreads();
    for (int s = THREADS / 2; s > 0; s >>= 1) {
        if (tid < s) {
            for (int k = 0; k < K; ++k) {
                sh[k * THREADS + tid] =
                    combine(ops[k], sh[k * THREADS + tid], sh[k * THREADS + tid + s]);
            }
        }
        __syncthreads();
    }
    if (tid == 0) {
        for (int k = 0; k < K; ++k) out[blockIdx.x * K + k] = sh[k * THREADS];
    }
}

#define FOR_EACH(i, n)                                                           \
    for (long long i = (long long)blockIdx.x * blockDim.x + threadIdx.x; i < (n); \
         i += (long long)gridDim.x * blockDim.x)

// ---------------------------------------------------------------------------------------------
// The elastic operator.

// X·asinh(Y/|X|) + Y·asinh(X/|Y|), each term 0 when its prefactor is 0 (solver/greens.rs).
__device__ double corner(double x, double y) {
    double a = x == 0.0 ? 0.0 : x * asinh(y / fabs(x));
    double b = y == 0.0 ? 0.0 : y * asinh(x / fabs(y));
    return a + b;
}

// Love's displacement at offset (x, y) from the centre of a dx × dy pixel under unit pressure.
__device__ double love_pixel(double x, double y, double dx, double dy, double e_star) {
    double a = 0.5 * dx, b = 0.5 * dy;
    return (corner(x + a, y + b) - corner(x + a, y - b) - corner(x - a, y + b) +
            corner(x - a, y - b)) /
           (3.14159265358979323846 * e_star);
}

// The free-boundary kernel on the padded fy × fx grid: offsets wrap at half the length.
extern "C" __global__ void love_kernel(double* out, int fy, int fx, double dx, double dy,
                                       double e_star) {
    long long n = (long long)fy * fx;
    FOR_EACH(i, n) {
        int y = (int)(i / fx), x = (int)(i % fx);
        int oy = y <= fy / 2 ? y : fy - y;
        int ox = x <= fx / 2 ? x : fx - x;
        out[i] = love_pixel(ox * dx, oy * dy, dx, dy, e_star);
    }
}

// The transfer function from the kernel's spectrum: its real part times the round-trip
// normalisation (the kernel is real and even, so its spectrum is real).
extern "C" __global__ void real_part(double* transfer, const double2* spectrum, long long n,
                                     double scale) {
    FOR_EACH(i, n) { transfer[i] = spectrum[i].x * scale; }
}

// The periodic multiplier 2/(E*|q|) (0 at q = 0) on the fy × (fx/2 + 1) half spectrum, with the
// round-trip normalisation.
extern "C" __global__ void periodic_transfer(double* transfer, int fy, int fx, double lx,
                                             double ly, double e_star, double scale) {
    int hx = fx / 2 + 1;
    long long n = (long long)fy * hx;
    FOR_EACH(i, n) {
        int ky = (int)(i / hx), kx = (int)(i % hx);
        int my = ky <= fy / 2 ? ky : ky - fy;
        double qx = 2.0 * 3.14159265358979323846 * kx / lx;
        double qy = 2.0 * 3.14159265358979323846 * my / ly;
        double q = hypot(qx, qy);
        transfer[i] = q == 0.0 ? 0.0 : 2.0 / (e_star * q) * scale;
    }
}

// buf (fy × fx) = src (h × w) in the top-left corner, 0 elsewhere.
extern "C" __global__ void pad(double* buf, int fy, int fx, const double* src, int h, int w) {
    long long n = (long long)fy * fx;
    FOR_EACH(i, n) {
        int y = (int)(i / fx), x = (int)(i % fx);
        buf[i] = (y < h && x < w) ? src[(long long)y * w + x] : 0.0;
    }
}

extern "C" __global__ void multiply(double2* spectrum, const double* transfer, long long n) {
    FOR_EACH(i, n) {
        double t = transfer[i];
        spectrum[i].x *= t;
        spectrum[i].y *= t;
    }
}

// dst (h × w) = the top-left h × w of buf (rows of fx).
extern "C" __global__ void crop(double* dst, int h, int w, const double* buf, int fx) {
    long long n = (long long)h * w;
    FOR_EACH(i, n) {
        int y = (int)(i / w), x = (int)(i % w);
        dst[i] = buf[(long long)y * fx + x];
    }
}

// out (oh × ow at oy0, ox0 of the grid) = the part of in (ih × iw at iy0, ix0) it overlaps,
// 0 elsewhere (Window::embed).
extern "C" __global__ void embed(double* out, int oy0, int ox0, int oh, int ow, const double* in,
                                 int iy0, int ix0, int ih, int iw) {
    long long n = (long long)oh * ow;
    FOR_EACH(i, n) {
        int y = oy0 + (int)(i / ow), x = ox0 + (int)(i % ow);
        bool inside = y >= iy0 && y < iy0 + ih && x >= ix0 && x < ix0 + iw;
        out[i] = inside ? in[(long long)(y - iy0) * iw + (x - ix0)] : 0.0;
    }
}

// ---------------------------------------------------------------------------------------------
// The passes of one iteration (cg/load/passes.rs).

// Sums and extremes of g' = e − delta per class, and the energy: 10 partials per block
// (count, sum, sum_sq, sum_gt, sum_t, free_min, free_max, zero_min, capped_max, energy).
extern "C" __global__ void gaps(double* out, const double* s, const double* u, const double* p,
                                const double* t, long long n, int mode, double compliance,
                                const double* bound, double delta) {
    Plastic pl = {mode, compliance, bound};
    double v[10] = {0.0, 0.0, 0.0, 0.0, 0.0, INF, -INF, INF, -INF, 0.0};
    const int ops[10] = {OP_SUM, OP_SUM, OP_SUM, OP_SUM, OP_SUM,
                         OP_MIN, OP_MAX, OP_MIN, OP_MAX, OP_SUM};
    FOR_EACH(i, n) {
        double pi = p[i], si = s[i], ui = u[i];
        double g = gap_of(pl, s, u, i, pi, delta);
        v[9] += pi * (si + 0.5 * ui) + spring_energy_of(pl, i, pi);
        if (pi <= 0.0) {
            v[7] = fmin(v[7], g);
        } else if (pi >= cap_of(pl, i)) {
            v[8] = fmax(v[8], g);
        } else {
            double ti = t[i];
            v[0] += 1.0;
            v[1] += g;
            v[2] += g * g;
            v[3] += g * ti;
            v[4] += ti;
            v[5] = fmin(v[5], g);
            v[6] = fmax(v[6], g);
        }
    }
    block_reduce<10>(v, ops, out);
}

// Σg² over the free pixels at approach delta.
extern "C" __global__ void residual_sq(double* out, const double* s, const double* u,
                                       const double* p, long long n, int mode, double compliance,
                                       const double* bound, double delta) {
    Plastic pl = {mode, compliance, bound};
    double v[1] = {0.0};
    const int ops[1] = {OP_SUM};
    FOR_EACH(i, n) {
        double pi = p[i];
        if (pi > 0.0 && pi < cap_of(pl, i)) {
            double g = gap_of(pl, s, u, i, pi, delta);
            v[0] += g * g;
        }
    }
    block_reduce<1>(v, ops, out);
}

// t ← (e − delta) + beta·t − mean on the free pixels, 0 elsewhere.
extern "C" __global__ void direction(double* t, const double* s, const double* u,
                                     const double* p, long long n, int mode, double compliance,
                                     const double* bound, double delta, double beta,
                                     double mean) {
    Plastic pl = {mode, compliance, bound};
    FOR_EACH(i, n) {
        double pi = p[i];
        if (pi > 0.0 && pi < cap_of(pl, i)) {
            t[i] = gap_of(pl, s, u, i, pi, delta) + beta * t[i] - mean;
        } else {
            t[i] = 0.0;
        }
    }
}

// Σ(r + t/k where the spring acts)·t over the free pixels.
extern "C" __global__ void curvature(double* out, const double* r, const double* t,
                                     const double* p, long long n, int mode, double compliance,
                                     const double* bound) {
    Plastic pl = {mode, compliance, bound};
    double v[1] = {0.0};
    const int ops[1] = {OP_SUM};
    FOR_EACH(i, n) {
        double pi = p[i];
        if (pi > 0.0 && pi < cap_of(pl, i)) {
            double ti = t[i];
            v[0] += (r[i] + spring_compliance_of(pl, i, pi) * ti) * ti;
        }
    }
    block_reduce<1>(v, ops, out);
}

// The projected step: 15 partials per block (total, inside, capped, min_inside, headroom,
// inside_total, capped_total, engaged, released, clamped, flipped, row_min, row_max, col_min,
// col_max).
extern "C" __global__ void step(double* out, double* p, double* previous, const double* s,
                                const double* u, const double* t, long long n, int width,
                                int mode, double compliance, const double* bound, double delta,
                                double tau) {
    Plastic pl = {mode, compliance, bound};
    double v[15] = {0.0, 0.0, 0.0, INF, INF, 0.0, 0.0, 0.0,
                    0.0, 0.0, 0.0, INF, -INF, INF, -INF};
    const int ops[15] = {OP_SUM, OP_SUM, OP_SUM, OP_MIN, OP_MIN, OP_SUM, OP_SUM, OP_SUM,
                         OP_SUM, OP_SUM, OP_SUM, OP_MIN, OP_MAX, OP_MIN, OP_MAX};
    FOR_EACH(i, n) {
        double old = p[i], cap = cap_of(pl, i);
        previous[i] = old;
        double next;
        if (old <= 0.0) {
            double g = gap_of(pl, s, u, i, old, delta);
            if (g < 0.0) {
                v[7] += 1.0;
                next = fmin(-tau * g, cap);
            } else {
                next = old;
            }
        } else if (old >= cap) {
            double g = gap_of(pl, s, u, i, old, delta);
            if (g > 0.0) {
                v[8] += 1.0;
                next = fmax(cap - tau * g, 0.0);
            } else {
                next = old;
            }
        } else {
            double stepped = old - tau * t[i];
            if (stepped >= cap) v[9] += 1.0;
            next = clamp_to(stepped, 0.0, cap);
        }
        bool soft_old = spring_compliance_of(pl, i, old) > 0.0;
        bool soft_new = spring_compliance_of(pl, i, next) > 0.0;
        if (soft_old != soft_new) v[10] += 1.0;
        if (next > 0.0) {
            double row = (double)(i / width), col = (double)(i % width);
            v[11] = fmin(v[11], row);
            v[12] = fmax(v[12], row);
            v[13] = fmin(v[13], col);
            v[14] = fmax(v[14], col);
        }
        if (next > 0.0 && next < cap) {
            v[1] += 1.0;
            v[5] += next;
            v[3] = fmin(v[3], next);
            v[4] = fmin(v[4], cap - next);
        } else if (next > 0.0) {
            v[2] += 1.0;
            v[6] += next;
        }
        p[i] = next;
        v[0] += next;
    }
    block_reduce<15>(v, ops, out);
}

// For a shift mu of the pixels strictly inside their bounds: 4 partials per block (the load
// after the shift, how many stay strictly inside, Σp over the others, Σcap over the inside ones).
extern "C" __global__ void shift_sums(double* out, const double* p, long long n, int mode,
                                      double compliance, const double* bound, double mu) {
    Plastic pl = {mode, compliance, bound};
    double v[4] = {0.0, 0.0, 0.0, 0.0};
    const int ops[4] = {OP_SUM, OP_SUM, OP_SUM, OP_SUM};
    FOR_EACH(i, n) {
        double pi = p[i], cap = cap_of(pl, i);
        if (pi > 0.0 && pi < cap) {
            double w = clamp_to(pi + mu, 0.0, cap);
            v[0] += w;
            if (w > 0.0 && w < cap) v[1] += 1.0;
            v[3] += cap;
        } else {
            v[0] += pi;
            v[2] += pi;
        }
    }
    block_reduce<4>(v, ops, out);
}

// Apply a shift (inside: clip(λp + μ, 0, cap); capped: λ_c·p): 2 partials per block
// (Σ|p − previous|, Σp).
extern "C" __global__ void apply_shift(double* out, double* p, const double* previous,
                                       long long n, int mode, double compliance,
                                       const double* bound, double inside_scale,
                                       double inside_add, double capped_scale) {
    Plastic pl = {mode, compliance, bound};
    double v[2] = {0.0, 0.0};
    const int ops[2] = {OP_SUM, OP_SUM};
    FOR_EACH(i, n) {
        double pi = p[i], cap = cap_of(pl, i);
        if (pi > 0.0 && pi < cap) {
            pi = clamp_to(pi * inside_scale + inside_add, 0.0, cap);
        } else if (pi > 0.0) {
            pi = pi * capped_scale;
        }
        p[i] = pi;
        v[0] += fabs(pi - previous[i]);
        v[1] += pi;
    }
    block_reduce<2>(v, ops, out);
}

// Σ|p − previous| and Σp.
extern "C" __global__ void change(double* out, const double* p, const double* previous,
                                  long long n) {
    double v[2] = {0.0, 0.0};
    const int ops[2] = {OP_SUM, OP_SUM};
    FOR_EACH(i, n) {
        v[0] += fabs(p[i] - previous[i]);
        v[1] += p[i];
    }
    block_reduce<2>(v, ops, out);
}

// Σmin(λp, cap) and Σp over the pixels with λp < cap.
extern "C" __global__ void start_sums(double* out, const double* p, long long n, int mode,
                                      double compliance, const double* bound, double lambda) {
    Plastic pl = {mode, compliance, bound};
    double v[2] = {0.0, 0.0};
    const int ops[2] = {OP_SUM, OP_SUM};
    FOR_EACH(i, n) {
        double cap = cap_of(pl, i);
        if (lambda * p[i] < cap) {
            v[0] += lambda * p[i];
            v[1] += p[i];
        } else {
            v[0] += cap;
        }
    }
    block_reduce<2>(v, ops, out);
}

// p ← min(a·p + b, cap): scaling (b = 0) and filling (a = 0).
extern "C" __global__ void affine(double* p, long long n, int mode, double compliance,
                                  const double* bound, double a, double b) {
    Plastic pl = {mode, compliance, bound};
    FOR_EACH(i, n) { p[i] = fmin(a == 0.0 ? b : a * p[i] + b, cap_of(pl, i)); }
}
