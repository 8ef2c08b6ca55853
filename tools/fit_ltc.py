#!/usr/bin/env python3
"""Fits linearly transformed cosines (Heitz, Dupuy, Hill, Neubelt 2016) to voxgi's GGX specular
lobe (crates/voxgi/shaders/shared/brdf.wgsl: GGX D, height-correlated Smith V, alpha =
roughness^2 floored at 0.045^2), Fresnel left out (the albedo table carries it).

For each cell of a 32 x 32 grid over (n.v, perceptual roughness) at texel centres, like
voxgi::brdf::TABLE_SIZE, it finds M such that the cosine distribution transformed by M matches
the lobe's normalised f cos, and writes M^-1 (normalised so that its [1][1] entry is 1) as
four little-endian f32 per cell (m00, m02, m20, m22 of M^-1, row-major, view in the xz plane)
to crates/voxgi/src/ltc_table.bin. Needs numpy and scipy; run from the repository root:

    python3 tools/fit_ltc.py
"""
import numpy as np
from scipy.optimize import minimize

SIZE = 32
M_SAMPLES = 32  # per axis, for each of the two sample sets


def ggx_alpha(r):
    return max(r, 0.045) ** 2


def brdf_cos(l, v, a):
    """f cos for unit l (N x 3) and v, F = 1."""
    nv = v[2]
    nl = l[:, 2]
    h = l + v
    h /= np.linalg.norm(h, axis=1, keepdims=True)
    nh = h[:, 2]
    a2 = a * a
    d = nh * nh * (a2 - 1.0) + 1.0
    dist = a2 / (np.pi * d * d)
    gv = nl * np.sqrt(nv * nv * (1.0 - a2) + a2)
    gl = nv * np.sqrt(np.maximum(nl * nl * (1.0 - a2) + a2, 0.0))
    vis = 0.5 / np.maximum(gv + gl, 1e-12)
    return np.where(nl > 0.0, dist * vis * nl, 0.0)


def samples(v, a):
    """Directions from GGX NDF sampling and from cosine sampling, with the mixture pdf."""
    u = (np.arange(M_SAMPLES) + 0.5) / M_SAMPLES
    u1, u2 = np.meshgrid(u, u)
    u1, u2 = u1.ravel(), u2.ravel()
    phi = 2.0 * np.pi * u2
    # NDF sampling of h, reflected.
    t2 = a * a * u1 / (1.0 - u1)
    ct = 1.0 / np.sqrt(1.0 + t2)
    st = np.sqrt(np.maximum(1.0 - ct * ct, 0.0))
    h = np.stack([st * np.cos(phi), st * np.sin(phi), ct], 1)
    vh = h @ v
    l1 = 2.0 * vh[:, None] * h - v
    # Cosine sampling.
    r = np.sqrt(u1)
    l2 = np.stack([r * np.cos(phi), r * np.sin(phi), np.sqrt(1.0 - u1)], 1)
    l = np.concatenate([l1, l2])
    l /= np.linalg.norm(l, axis=1, keepdims=True)
    return l, mixture_pdf(l, v, a)


def mixture_pdf(l, v, a):
    h = l + v
    hn = np.linalg.norm(h, axis=1, keepdims=True)
    h = h / np.maximum(hn, 1e-12)
    nh = np.maximum(h[:, 2], 0.0)
    a2 = a * a
    d = nh * nh * (a2 - 1.0) + 1.0
    dist = a2 / (np.pi * d * d)
    vh = np.maximum(h @ v, 1e-9)
    p_ndf = dist * nh / (4.0 * vh)
    p_cos = np.maximum(l[:, 2], 0.0) / np.pi
    return np.maximum(0.5 * p_ndf + 0.5 * p_cos, 1e-12)


def ltc_eval(m, l):
    """The cosine distribution transformed by m, at unit directions l."""
    minv = np.linalg.inv(m)
    lo = l @ minv.T
    length = np.linalg.norm(lo, axis=1)
    lo_z = lo[:, 2] / length
    jac = abs(np.linalg.det(minv)) / length ** 3
    return np.maximum(lo_z, 0.0) / np.pi * jac


def average_direction(l, w):
    d = (l * w[:, None]).sum(0)
    d[1] = 0.0
    return d / np.linalg.norm(d)


def matrix(p, frame):
    # Heitz et al.'s isotropic parameters in the frame of the lobe's average direction.
    a, c, b = p
    return frame @ np.array([[a, 0.0, b], [0.0, c, 0.0], [0.0, 0.0, 1.0]])


def ltc_samples(m):
    """Cosine-distributed directions mapped by m: samples of the LTC itself."""
    u = (np.arange(M_SAMPLES) + 0.5) / M_SAMPLES
    u1, u2 = np.meshgrid(u, u)
    u1, u2 = u1.ravel(), u2.ravel()
    r = np.sqrt(u1)
    phi = 2.0 * np.pi * u2
    wo = np.stack([r * np.cos(phi), r * np.sin(phi), np.sqrt(1.0 - u1)], 1)
    w = wo @ m.T
    return w / np.linalg.norm(w, axis=1, keepdims=True)


def brdf_pdf(l, v, a):
    h = l + v
    h = h / np.maximum(np.linalg.norm(h, axis=1, keepdims=True), 1e-12)
    nh = np.maximum(h[:, 2], 0.0)
    a2 = a * a
    d = nh * nh * (a2 - 1.0) + 1.0
    dist = a2 / (np.pi * d * d)
    vh = np.maximum(h @ v, 1e-9)
    return dist * nh / (4.0 * vh)


def fit_cell(nv, r, p0):
    a = ggx_alpha(r)
    v = np.array([np.sqrt(1.0 - nv * nv), 0.0, nv])
    l, pdf = samples(v, a)
    f = brdf_cos(l, v, a)
    albedo = (f / pdf).mean()
    avg = average_direction(l, f / pdf)
    x = np.array([avg[2], 0.0, -avg[0]])
    frame = np.stack([x, [0.0, 1.0, 0.0], avg], 1)
    # BRDF samples: NDF sampling of the reflected direction (fixed); LTC samples follow m.
    lb = l[: M_SAMPLES * M_SAMPLES]
    fb = f[: M_SAMPLES * M_SAMPLES] / albedo
    pb = brdf_pdf(lb, v, a)

    def err(p):
        if p[0] <= 1e-6 or p[1] <= 1e-6:
            return 1e30
        m = matrix(p, frame)
        ll = ltc_samples(m)
        fl = brdf_cos(ll, v, a) / albedo
        e = 0.0
        for dirs, target in ((lb, fb), (ll, fl)):
            dl = ltc_eval(m, dirs)
            mix = 0.5 * brdf_pdf(dirs, v, a) + 0.5 * dl
            e += (np.abs(dl - target) ** 3 / np.maximum(mix, 1e-12)).mean()
        return e

    best = minimize(err, p0, method="Nelder-Mead",
                    options={"xatol": 1e-7, "fatol": 1e-12, "maxiter": 4000, "maxfev": 8000})
    return best.x, matrix(best.x, frame), best.fun


def main():
    table = np.zeros((SIZE, SIZE, 4), np.float32)
    # From rough to smooth; each roughness from front view to grazing, warm-started from the
    # previous cell (Heitz et al.'s order).
    p_first = None
    for j in reversed(range(SIZE)):
        r = (j + 0.5) / SIZE
        a = ggx_alpha(r)
        if p_first is None:
            p = np.array([a, a, 0.0])
        else:
            prev_a = ggx_alpha((j + 1.5) / SIZE)
            p = np.array([p_first[0] * a / prev_a, p_first[1] * a / prev_a, p_first[2]])
        for ii in reversed(range(SIZE)):
            nv = (ii + 0.5) / SIZE
            p, m, e = fit_cell(nv, r, p)
            if ii == SIZE - 1:
                p_first = p.copy()
            minv = np.linalg.inv(m)
            minv /= minv[1, 1]
            table[j, ii] = [minv[0, 0], minv[0, 2], minv[2, 0], minv[2, 2]]
        print(f"roughness {r:.3f}: last error {e:.3e}", flush=True)
    table.astype("<f4").tofile("crates/voxgi/src/ltc_table.bin")
    print("wrote crates/voxgi/src/ltc_table.bin")


if __name__ == "__main__":
    main()
