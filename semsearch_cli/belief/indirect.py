"""The probability map of the main object A in indirect search (Loncomilla et al. 2018, Section 3).

The map holds p(a_ij) over the room's cells and p(a_0), the outside cell (Eqs. 6-9). Every
observation multiplies it by a likelihood image (and the outside cell by a number) and
renormalises:

- A not seen (Eqs. 6-7): ``1 - D_A``, D_A the robot's model of detecting A in each cell from the
  pose (:class:`~semsearch_cli.sensors.indirect.YawMemory`: the probability of detecting A in this
  frame given the frames before missed it); the outside cell 1.
- B seen at cell c (Eqs. 8-9, 12-13): the likelihood image of B is 1 at c and 0 elsewhere, so the
  cross-likelihood (Eq. 14) is the relation mask centred on c, R_B/A(ij - c) / S(ij), and the
  outside cell gets the image's mean, 1 / n (Eq. 13 as we read it).
- B not seen (Eqs. 8-9, 12-13): the likelihood image is ``1 - D_B`` (D_B as D_A); its convolution with the
  relation is ``1 - (D_B * R_B/A) / S``, done by FFT; the outside cell gets the image's mean.

S(ij) = sum over the map's cells uv of R_B/A(ij - uv), computed once: given A at ij, B stands in
the room (as Eq. 11 has it for the outside cell), so p(b_uv | a_ij) is the mask renormalised over
the map. Eq. 12 as printed sums the mask over the map without it; S is then below 1 near the walls
(part of the ring falls outside), and every frame in which B is not seen would push probability
away from the walls for no reason.

Relation masks (Eqs. 18-32). A basic mask is a function of the offset between two cells, hard
(rectangular profile) or soft (trapezoid, the gap delta), over every offset two cells of the map can
have ((2H - 1) x (2W - 1)), normalised to sum 1 there. A class's mask mixes the four basic masks by
its co-occurrences (Eq. 28 with our reading of Eq. 32). The "very far" mask reaches the whole
map, so a convolution with it would cost a map-sized kernel: we write each mixed mask as a local
part (within u3 + delta) plus a constant, R = l + kappa, so that D * R = D * l + kappa sum(D), and
only the local part is convolved.

The convolutions run in single precision (they are the cost of PN search); S and the map are
double. Observations are kept and folded in batches (:meth:`IndirectBelief.flush`): products commute, and
renormalising once per batch gives the same map as renormalising at every frame, up to rounding.
The planners read the map only when they re-plan, which flushes; the batch turns a frame's three
small FFTs into one stacked FFT per batch.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.fft as sfft

from ..config.indirect import CATEGORIES, MasksSpec


# ---- relation masks ---------------------------------------------------------------------------
def offsets(res: float, H: int, W: int) -> np.ndarray:
    """(2H - 1, 2W - 1) distances (m) of every offset two cells of an H x W map can have; the
    centre is the zero offset."""
    di = np.arange(-(H - 1), H) * res
    dj = np.arange(-(W - 1), W) * res
    return np.hypot(di[:, None], dj[None, :])


def hard_profile(d: np.ndarray, a1: float, a2: float) -> np.ndarray:
    """Eq. 18 before normalising: 1 on a1 <= d < a2."""
    return ((d >= a1) & (d < a2)).astype(float)


def soft_profile(d: np.ndarray, a1: float, a2: float, a3: float, a4: float) -> np.ndarray:
    """Eq. 19 before normalising: rising on [a1, a2), 1 on [a2, a3), falling on [a3, a4)."""
    out = np.zeros_like(d, dtype=float)
    if a2 > a1:
        m = (d >= a1) & (d < a2)
        out[m] = (d[m] - a1) / (a2 - a1)
    out[(d >= a2) & (d < a3)] = 1.0
    if np.isfinite(a4) and a4 > a3:
        m = (d >= a3) & (d < a4)
        out[m] = (a4 - d[m]) / (a4 - a3)
    elif not np.isfinite(a4):
        out[d >= a3] = 1.0
    return out


def basic_profiles(kind: str, m: MasksSpec, d: np.ndarray) -> dict[str, np.ndarray]:
    """Unnormalised basic masks VN, N, F, VF (Eqs. 20-23 hard, 24-27 soft) at distances ``d``."""
    u1, u2, u3, g = m.u1, m.u2, m.u3, m.gap
    inf = np.inf
    if kind == "hard":
        return {"VN": hard_profile(d, 0.0, u1), "N": hard_profile(d, u1, u2), "F": hard_profile(d, u2, u3),
                "VF": hard_profile(d, u3, inf)}
    if kind == "soft":
        return {"VN": soft_profile(d, 0.0, 0.0, u1 - g, u1 + g), "N": soft_profile(d, u1 - g, u1 + g, u2 - g, u2 + g),
                "F": soft_profile(d, u2 - g, u2 + g, u3 - g, u3 + g), "VF": soft_profile(d, u3 - g, u3 + g, inf, inf)}
    raise ValueError(f"mask kind must be hard or soft, not {kind!r}")


def basic_masks(kind: str, m: MasksSpec, res: float, H: int, W: int) -> dict[str, np.ndarray]:
    """The four basic masks over every offset of an H x W map, each summing to 1."""
    prof = basic_profiles(kind, m, offsets(res, H, W))
    return {q: p / p.sum() for q, p in prof.items()}


def mixed_mask(kind: str, m: MasksSpec, co: tuple, res: float, H: int, W: int) -> np.ndarray:
    """Eq. 28: a class's mask, the basic masks weighted by its co-occurrences (VN, N, F, VF)."""
    b = basic_masks(kind, m, res, H, W)
    return sum(c * b[q] for c, q in zip(co, CATEGORIES))


@dataclass
class RelationMask:
    """A class's mixed mask split as R = local + kappa (see the module's docstring), with what
    the convolutions need: the local kernel's FFT at the padded size, and S."""

    kappa: float
    full_centre: tuple[int, int]
    full: np.ndarray  # the whole mixed mask, for positive detections
    S: np.ndarray  # (H, W) the mask's mass on the map from each cell
    fft: np.ndarray  # rfft2 of the local kernel, wrapped, at the padded size (single precision)
    shape: tuple[int, int]  # padded size


def relation_mask(kind: str, m: MasksSpec, co: tuple, res: float, H: int, W: int) -> RelationMask:
    d = offsets(res, H, W)
    prof = basic_profiles(kind, m, d)
    sums = {q: p.sum() for q, p in prof.items()}
    full = sum(c * prof[q] / sums[q] for c, q in zip(co, CATEGORIES))
    # VF = K (1 - g) with g local (1 inside u3, soft edge): R = local + kappa
    kappa = co[3] / sums["VF"]
    local_full = full - kappa
    reach = m.u3 + (m.gap if kind == "soft" else 0.0)
    r = int(np.ceil(reach / res)) + 1
    r = min(r, H - 1, W - 1) if min(H, W) > 1 else 0
    ci, cj = H - 1, W - 1
    local = local_full[ci - r:ci + r + 1, cj - r:cj + r + 1].copy()
    # outside the local window the local part must vanish (else the split is not exact)
    rest = local_full.copy()
    rest[ci - r:ci + r + 1, cj - r:cj + r + 1] = 0.0
    if np.abs(rest).max(initial=0.0) > 1e-12 * max(1.0, np.abs(full).max()):
        raise ValueError("relation mask: the local window does not hold the local part")
    shape = (sfft.next_fast_len(H + r, real=True), sfft.next_fast_len(W + r, real=True))
    k = np.zeros(shape)
    ii, jj = np.meshgrid(np.arange(-r, r + 1), np.arange(-r, r + 1), indexing="ij")
    k[ii % shape[0], jj % shape[1]] = local
    ones = np.zeros(shape)
    ones[:H, :W] = 1.0
    S = sfft.irfft2(sfft.rfft2(ones) * sfft.rfft2(k), s=shape)[:H, :W] + kappa * H * W
    return RelationMask(float(kappa), (ci, cj), full, S, sfft.rfft2(k.astype(np.float32)), shape)


def convolve_local(images: np.ndarray, mask: RelationMask) -> np.ndarray:
    """(k, H, W) images convolved with the mask's local part ('same' size), by one stacked FFT in
    single precision (relative error about 1e-7; the map itself stays in double precision)."""
    k, H, W = images.shape
    pad = np.zeros((k, *mask.shape), np.float32)
    pad[:, :H, :W] = images
    return sfft.irfft2(sfft.rfft2(pad, axes=(-2, -1)) * mask.fft, s=mask.shape, axes=(-2, -1))[:, :H, :W]


# ---- the probability map ----------------------------------------------------------------------
class IndirectBelief:
    """p(a_ij) on an H x W map and p(a_0), the outside cell.

    Parameters
    ----------
    shape : (H, W)
    masks : class -> :class:`RelationMask` (empty for uninformed search)
    prior : (H, W) p(a_ij) before any observation (zeros where A cannot be, e.g. obstacles);
        normalised with ``p_outside`` so that the map and the outside cell sum to 1
    p_outside : float, the outside cell's prior
    coarse : the secondary objects' non-detections are taken on a grid ``coarse`` times coarser
        (``coarse_masks`` are built at that grid): their detection images are given at the coarse
        cells' centres, convolved there, and the likelihood is spread back over each block's
        cells; 1 is exact. The relation masks are rings 0.4 m wide and more, so at 2 the
        likelihood moves by little (tests/test_indirect.py bounds it) and the work is a quarter.
    """

    def __init__(self, shape, masks: dict[str, RelationMask], prior: np.ndarray, p_outside: float,
                 coarse: int = 1, coarse_masks: dict[str, RelationMask] | None = None):
        self.H, self.W = shape
        self.masks = masks
        self.coarse = int(coarse)
        self.neg_masks = masks if self.coarse == 1 else coarse_masks
        if self.coarse > 1 and (self.H % self.coarse or self.W % self.coarse or coarse_masks is None):
            raise ValueError("coarse needs masks at the coarse grid and a map whose sides it divides")
        prior = np.asarray(prior, float)
        self.p = prior / prior.sum() * (1.0 - p_outside)
        self.p0 = float(p_outside)
        self.n = self.H * self.W
        self._factor = np.ones(shape)  # product of the pending likelihood images
        self._factor0 = 1.0
        self._negatives: dict[str, list[np.ndarray]] = {c: [] for c in masks}

    # ---- observations (pending until flush) --------------------------------------------------
    def not_seen_main(self, D: np.ndarray) -> None:
        """A not seen (Eqs. 6-7): likelihood ``1 - D`` in the map, 1 outside."""
        self._factor *= 1.0 - D

    def seen_secondary(self, cls: str, row: int, col: int, false_positive: float = 0.0) -> None:
        """B seen at cell (row, col) (Eqs. 8-9, 12-13): the mask centred there; outside, 1/n.
        With a detector that reports B where it is not at rate ``false_positive`` (eps), the
        likelihood image is (1 - eps) at the cell plus eps / n everywhere, which gives the map
        (1 - eps) mask / S + eps / n and the outside cell 1/n still."""
        m = self.masks[cls]
        ci, cj = m.full_centre
        like = m.full[ci - row:ci - row + self.H, cj - col:cj - col + self.W] / m.S
        self._factor *= like if not false_positive else (1.0 - false_positive) * like + false_positive / self.n
        self._factor0 *= 1.0 / self.n

    @property
    def negative_shape(self) -> tuple[int, int]:
        """The grid of :meth:`not_seen_secondary`'s images: the map's, or ``coarse`` times coarser."""
        return self.H // self.coarse, self.W // self.coarse

    def not_seen_secondary(self, cls: str, D: np.ndarray) -> None:
        """B not seen (Eqs. 8-9, 12-13): the convolution of ``1 - D`` with the mask (folded at
        :meth:`flush`); outside, the mean of ``1 - D``. ``D`` is on :attr:`negative_shape`."""
        self._negatives[cls].append(D)

    def flush(self) -> None:
        """Fold the pending observations into the map and renormalise."""
        f = self._factor
        f0 = self._factor0
        for cls, Ds in self._negatives.items():
            if not Ds:
                continue
            m = self.neg_masks[cls]
            q = self.coarse
            stack = np.stack(Ds)
            conv = convolve_local(stack, m)
            sums = stack.sum(axis=(1, 2))
            like = np.clip(1.0 - (conv + m.kappa * sums[:, None, None]) / m.S[None], 0.0, None).prod(axis=0)
            if q > 1:
                like = np.repeat(np.repeat(like, q, axis=0), q, axis=1)
            f = f * like
            f0 *= float(np.prod(1.0 - sums * (q * q) / self.n))
            Ds.clear()
        p = self.p * f
        p0 = self.p0 * f0
        z = p.sum() + p0
        if z > 0:
            self.p, self.p0 = p / z, p0 / z
        self._factor = np.ones((self.H, self.W))
        self._factor0 = 1.0

    def probability(self) -> tuple[np.ndarray, float]:
        """(p(a_ij), p(a_0)) after folding in everything observed so far."""
        self.flush()
        return self.p, self.p0

    def inside(self) -> np.ndarray:
        """(H, W) float32: p(a_ij) given that the target is in the room (the map scaled to sum to
        1), after folding in everything observed so far: what the environment and the llm
        planner show."""
        self.flush()
        return (self.p / max(float(self.p.sum()), 1e-300)).astype(np.float32)
