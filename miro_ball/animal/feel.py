"""Touch as an animal feels it: strokes, a still hand, hits.

Each part (head, body) has its pads in two rows along it (miro.touch): where a hand is
along the part is the mean column of the pads it covers. A stroke is the hand moving
stroke_pads columns along while it stays in contact; a still hand is a pet; a hit is
many pads (hit_pads) touched at once out of nothing, as a slap does.
"""
from typing import NamedTuple

from miro_ball.miro.touch import TOUCH_COLUMNS, pads_touched


class Touches(NamedTuple):
    strokes: int = 0  # strokes completed this tick
    pet: bool = False  # a hand is on, not stroking
    hits: int = 0
    touched: bool = False  # any contact at all


def _column(mask):
    pads = pads_touched(mask)
    return sum(pad % TOUCH_COLUMNS for pad in pads) / len(pads)


class PartFeel:
    """One part's touch over time."""

    def __init__(self):
        self.previous = 0
        self.anchor = None  # where along the part the current stroke started (column)

    def feel(self, mask, stroke_pads, hit_pads):
        previous, self.previous = self.previous, mask
        if not mask:
            self.anchor = None
            return Touches()
        hits = int(not previous and bin(mask).count('1') >= hit_pads)
        column = _column(mask)
        if self.anchor is None:
            self.anchor = column
        strokes = 0
        if abs(column - self.anchor) >= stroke_pads:
            strokes, self.anchor = 1, column
        return Touches(strokes, pet=not strokes and not hits, hits=hits, touched=True)


class Feel:
    """Head and body together; masks restrict each to the pads that count."""

    def __init__(self, params):
        self.params = params
        self.parts = {'head': PartFeel(), 'body': PartFeel()}

    def feel(self, head, body):
        p = self.params
        felt = [self.parts['head'].feel((head or 0) & p.head_pads, p.stroke_pads, p.hit_pads),
                self.parts['body'].feel((body or 0) & p.body_pads, p.stroke_pads, p.hit_pads)]
        return Touches(sum(t.strokes for t in felt), any(t.pet for t in felt),
                       sum(t.hits for t in felt), any(t.touched for t in felt))
