"""When the command line's view of the ROS graph is whole enough to answer from.

Without ``ros2``'s daemon, a fresh node hears of the other processes one by one: each
answers a newcomer at once or only with its next periodic announcement (Fast DDS sends
one every 3 s), so the last of them is heard of up to 3 s after the start (measured:
12 runs beside a simulator, a controller and a Foxglove bridge, the last heard of at
0.06 to 2.98 s, spread evenly), and each one's endpoints come a moment before the names
of the nodes they belong to. A listing is the answer once the graph is consistent (every
endpoint has its node, every node has endpoints), has been listened to for MIN_S, and
has not changed for STABLE_S; at LIMIT_S it is said to be perhaps incomplete rather than
passed off as whole.

Times are passed in (wall seconds): pure logic, tested without ROS.
"""

MIN_S = 3.5  # wall seconds a listing listens at least: one announcement period, and some
STABLE_S = 1.0  # ... and stays the same (endpoints of a process come one after another)
LIMIT_S = 10.0  # ... and at most: then it is answered, with a word that it may be partial


class Settling:
    """Follows one listing of the graph from start; see() says when it is the answer."""

    def __init__(self, start):
        self.start = start
        self.listing = None
        self.changed = start
        self.whole = False  # the listing seen last is, as far as can be known, all of it

    def see(self, now, listing, consistent):
        """True when listing (seen at now; consistent: every endpoint has its node and
        every node its endpoints) is the answer (whole), or the time limit is reached."""
        if listing != self.listing:
            self.listing, self.changed = listing, now
        self.whole = (consistent and now - self.start >= MIN_S
                      and now - self.changed >= STABLE_S)
        return self.whole or now - self.start >= LIMIT_S


def incomplete_line(seconds):
    """What stderr says when a listing is answered at the limit."""
    return (f'the ROS graph was still changing after {seconds:g} s of listening: this '
            'listing may be incomplete (run it again)')
