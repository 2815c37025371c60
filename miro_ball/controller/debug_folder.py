"""--save-debug's folder: the newest annotated frames only, so a long run cannot fill the disk."""
import os
from collections import deque


class DebugFolder:
    """Writes files into path and deletes the oldest it wrote beyond `keep`."""

    def __init__(self, path, keep):
        self.path = path
        self.keep = keep
        self._written = deque()

    def save(self, name, data):
        """Write data as path/name (OSError passes up), then drop the oldest over the limit."""
        target = os.path.join(self.path, name)
        with open(target, 'wb') as out:
            out.write(data)
        self._written.append(target)
        while len(self._written) > self.keep:
            try:
                os.remove(self._written.popleft())
            except FileNotFoundError:  # someone tidied up already
                pass
