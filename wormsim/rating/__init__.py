"""Load-capacity rating of worm gears: ISO/TS 14521 / DIN 3996 method B and AGMA 6034 as publicly reproduced, the
FE tooth-root stress of the wheel (wormsim.rating.fe_root), and the rating.json / rating.md writers. Formulas and
sources: docs/rating.md."""

from wormsim.rating.rate import RATING_KEYS, rate

__all__ = ["RATING_KEYS", "rate"]
