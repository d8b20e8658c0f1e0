"""Box, the one space the environment needs: gymnasium.spaces.Box when gymnasium is importable
(it is not a Debian package; Caliper does not depend on it), else a class with the same
constructor, attributes and methods (shape, dtype, low, high, sample, contains, seed)."""

from __future__ import annotations

from typing import Optional, Sequence, Tuple, Union

import numpy as np

__all__ = ["Box", "GYMNASIUM"]

try:  # pragma: no cover - depends on the machine
    import gymnasium
    Box = gymnasium.spaces.Box
    GYMNASIUM = True
except ImportError:
    GYMNASIUM = False

    class Box:  # type: ignore[no-redef]
        """A box in R^n: `low` <= x <= `high` element-wise (gymnasium.spaces.Box's API)."""

        def __init__(self, low: Union[float, Sequence[float], np.ndarray],
                     high: Union[float, Sequence[float], np.ndarray],
                     shape: Optional[Tuple[int, ...]] = None, dtype=np.float64,
                     seed: Optional[int] = None):
            self.dtype = np.dtype(dtype)
            if shape is None:
                shape = np.shape(low) if np.ndim(low) else np.shape(high)
            self.shape: Tuple[int, ...] = tuple(int(s) for s in shape)
            self.low = np.broadcast_to(np.asarray(low, dtype=self.dtype), self.shape).copy()
            self.high = np.broadcast_to(np.asarray(high, dtype=self.dtype), self.shape).copy()
            if np.any(self.low > self.high):
                raise ValueError("low must be <= high")
            self.np_random = np.random.default_rng(seed)

        def seed(self, seed: Optional[int] = None) -> list:
            """Reseeds sample()'s generator."""
            self.np_random = np.random.default_rng(seed)
            return [seed]

        def sample(self) -> np.ndarray:
            """Uniform in bounded dimensions, normal where unbounded (gymnasium's rule, half
            bounded ones as exponential)."""
            low, high = self.low, self.high
            out = np.empty(self.shape, dtype=self.dtype)
            bounded = np.isfinite(low) & np.isfinite(high)
            below = np.isfinite(low) & ~np.isfinite(high)
            above = ~np.isfinite(low) & np.isfinite(high)
            free = ~np.isfinite(low) & ~np.isfinite(high)
            out[bounded] = self.np_random.uniform(low[bounded], high[bounded])
            out[below] = low[below] + self.np_random.exponential(size=below.sum())
            out[above] = high[above] - self.np_random.exponential(size=above.sum())
            out[free] = self.np_random.normal(size=free.sum())
            return out

        def contains(self, x) -> bool:
            """Whether `x` has the box's shape and lies within its bounds."""
            x = np.asarray(x)
            return bool(x.shape == self.shape and np.can_cast(x.dtype, self.dtype) and
                        np.all(x >= self.low) and np.all(x <= self.high))

        def __contains__(self, x) -> bool:
            return self.contains(x)

        def is_bounded(self, manner: str = "both") -> bool:
            """Whether every dimension is bounded ("both", "below" or "above")."""
            below, above = np.all(np.isfinite(self.low)), np.all(np.isfinite(self.high))
            return {"both": below and above, "below": below, "above": above}[manner]

        def __repr__(self) -> str:
            return f"Box({self.low.min()}, {self.high.max()}, {self.shape}, {self.dtype})"

        def __eq__(self, other) -> bool:
            return (isinstance(other, Box) and self.shape == other.shape and
                    np.array_equal(self.low, other.low) and np.array_equal(self.high, other.high))
