"""tdm: target detection module. Turns raysim (or real) recordings into detected targets.

It never imports raysim: it reads recordings only (docs/contracts.md), so it runs unchanged on
real sensor recordings. This version holds the recording readers; the front ends,
trackers, fusion and evaluation arrive with the TDM issue.
"""

__version__ = "0.1.0"
