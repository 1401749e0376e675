"""Generates the MSSIM / RMSE / PSNR / FLIP fixtures for runtime/tests/metrics.rs.

Run from this directory with Python 3, numpy, scipy, scikit-image and NVIDIA's
flip-evaluator (pip install scikit-image flip-evaluator); it rewrites the
*.rgba32f images and expected.json here. Versions used for the committed files
are recorded in expected.json.

Images are raw little-endian f32 RGBA, row-major, top row first, no header.
All expected values are computed in float64 from the f32 values as stored.

MSSIM is computed on the luminance plane Y = 0.2126 R + 0.7152 G + 0.0722 B of
the channels clamped to [0, 1] (the definition in runtime/src/metrics.rs), in
three independent ways that must agree to 1e-12 before anything is written:
  * "mssim_skimage": skimage.metrics.structural_similarity with
    gaussian_weights=True, sigma=1.5, use_sample_covariance=False,
    data_range=1.0. skimage filters with reflect padding over the whole image
    and then crops (win_size - 1) // 2 = 5 pixels from every side before
    averaging, which leaves exactly the (W-10)x(H-10) positions whose 11x11
    window lies inside the image, i.e. MATLAB's filter2(..., 'valid').
  * "mssim" (the value the Rust test asserts): a direct transcription of Wang's
    ssim_index.m with an explicit 'valid' 2D correlation (no padding at all),
    using the normalised 11x11 Gaussian (sigma 1.5) and K1 = 0.01, K2 = 0.03,
    L = 1.
  * skimage's full SSIM map (full=True) cropped by hand to [5:-5, 5:-5].
FLIP ("flip_mean") is NVIDIA's flip_evaluator.evaluate in LDR mode on the
sRGB 8-bit quantisation of the linear values (clamp to [0, 1], sRGB OETF,
round(255 v)), at the default 67.02 pixels per degree.
"""

import json

import numpy as np
import scipy
import scipy.ndimage as ndi
import skimage
from skimage.metrics import structural_similarity

import flip_evaluator

SIZES = [(32, 24), (64, 48)]


def luminance(img):
    c = np.clip(img[..., :3].astype(np.float64), 0.0, 1.0)
    return 0.2126 * c[..., 0] + 0.7152 * c[..., 1] + 0.0722 * c[..., 2]


def gaussian_window():
    x = np.arange(11, dtype=np.float64) - 5.0
    g = np.exp(-(x * x) / (2.0 * 1.5 * 1.5))
    w = np.outer(g, g)
    return w / w.sum()  # fspecial('gaussian', 11, 1.5) / sum


def filter2_valid(window, img):
    win = np.lib.stride_tricks.sliding_window_view(img, window.shape)
    return np.einsum("ijkl,kl->ij", win, window)


def ssim_index_m(a, b):
    """ssim_index.m (Wang 2004) with L = 1, returning mean(ssim_map)."""
    window = gaussian_window()
    c1, c2 = (0.01 * 1.0) ** 2, (0.03 * 1.0) ** 2
    mu1, mu2 = filter2_valid(window, a), filter2_valid(window, b)
    mu1_sq, mu2_sq, mu1_mu2 = mu1 * mu1, mu2 * mu2, mu1 * mu2
    s1 = filter2_valid(window, a * a) - mu1_sq
    s2 = filter2_valid(window, b * b) - mu2_sq
    s12 = filter2_valid(window, a * b) - mu1_mu2
    ssim_map = ((2 * mu1_mu2 + c1) * (2 * s12 + c2)) / ((mu1_sq + mu2_sq + c1) * (s1 + s2 + c2))
    assert ssim_map.shape == (a.shape[0] - 10, a.shape[1] - 10)
    return float(ssim_map.mean())


def skimage_mssim(a, b):
    kw = dict(gaussian_weights=True, sigma=1.5, use_sample_covariance=False, data_range=1.0)
    m = structural_similarity(a, b, **kw)
    _, full = structural_similarity(a, b, full=True, **kw)
    return float(m), float(full[5:-5, 5:-5].mean())


def to_srgb8(img):
    c = np.clip(img[..., :3].astype(np.float64), 0.0, 1.0)
    s = np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(c, 1.0 / 2.4) - 0.055)
    return np.floor(s * 255.0 + 0.5).astype(np.uint8)


def flip_mean(test, reference):
    ref = to_srgb8(reference).astype(np.float32) / 255.0
    tst = to_srgb8(test).astype(np.float32) / 255.0
    _, mean, _ = flip_evaluator.evaluate(ref, tst, "LDR", inputsRGB=True, applyMagma=False)
    return float(mean)


def make_images(w, h, seed):
    y, x = np.mgrid[0:h, 0:w].astype(np.float64)
    ref = np.empty((h, w, 4))
    ref[..., 0] = x / (w - 1)
    ref[..., 1] = y / (h - 1)
    ref[..., 2] = 0.5 + 0.4 * np.sin(2 * np.pi * x / 8.0) * np.cos(2 * np.pi * y / 12.0)
    ref[..., 3] = 1.0
    rng = np.random.default_rng(seed)
    noisy = ref.copy()
    noisy[..., :3] += rng.normal(0.0, 0.05, size=(h, w, 3))  # some values leave [0, 1]
    blurred = ref.copy()
    for c in range(3):
        blurred[..., c] = ndi.gaussian_filter(ref[..., c], sigma=1.0, mode="nearest")
    offset = ref.copy()
    offset[..., :3] += 0.1  # the red and green ramps pass 1.0
    tests = {"noisy": noisy, "blurred": blurred, "offset": offset}
    for t in tests.values():
        t[..., 3] = 0.25  # alpha must be ignored
    return ref.astype("<f4"), {k: v.astype("<f4") for k, v in tests.items()}


def main():
    cases = []
    for i, (w, h) in enumerate(SIZES):
        ref, tests = make_images(w, h, seed=20040401 + i)
        ref_name = f"gradient_{w}x{h}.rgba32f"
        ref.tofile(ref_name)
        for name, img in tests.items():
            file = f"{name}_{w}x{h}.rgba32f"
            img.tofile(file)
            back = np.fromfile(file, dtype="<f4").reshape(h, w, 4)
            a, b = luminance(back), luminance(np.fromfile(ref_name, dtype="<f4").reshape(h, w, 4))
            m = ssim_index_m(a, b)
            sk, sk_full = skimage_mssim(a, b)
            assert abs(m - sk) < 1e-12 and abs(m - sk_full) < 1e-12, (m, sk, sk_full)
            d = back[..., :3].astype(np.float64) - ref[..., :3].astype(np.float64)
            mse = float(np.mean(d * d))
            cases.append(
                dict(
                    width=w,
                    height=h,
                    reference=ref_name,
                    test=file,
                    mssim=m,
                    mssim_skimage=sk,
                    rmse=mse**0.5,
                    psnr=10.0 * np.log10(1.0 / mse),
                    flip_mean=flip_mean(back, ref),
                )
            )
    meta = dict(
        numpy=np.__version__,
        scipy=scipy.__version__,
        skimage=skimage.__version__,
        flip_evaluator="1.7",
    )
    with open("expected.json", "w") as f:
        json.dump(dict(generator="gen_fixtures.py", versions=meta, cases=cases), f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
