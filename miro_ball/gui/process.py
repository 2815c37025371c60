"""miro_gui as a child process, as tests and benchmarks start it: on a free port, its URL
read from what it prints, its output drained all along (so it never blocks on a full
pipe) and kept for a look afterwards."""
import collections
import queue
import subprocess
import sys
import threading

START_TIMEOUT_S = 30.0


class GuiProcess:
    def __init__(self, env, args=('--port', '0'), timeout_s=START_TIMEOUT_S):
        self.proc = subprocess.Popen([sys.executable, '-m', 'miro_ball.gui', *args], env=env,
                                     stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                     text=True)
        self.output = collections.deque(maxlen=1000)
        urls = queue.Queue()
        threading.Thread(target=self._drain, args=(urls,), daemon=True).start()
        try:
            self.url = urls.get(timeout=timeout_s)
        except queue.Empty:
            self.url = None
        if self.url is None:
            self.stop()
            raise RuntimeError('miro_gui printed no URL:\n' + ''.join(self.output))

    def _drain(self, urls):
        for line in self.proc.stdout:
            self.output.append(line)
            if 'open http://' in line:
                urls.put(line.split('open ', 1)[1].strip())
        urls.put(None)  # it ended

    @property
    def pid(self):
        return self.proc.pid

    def stop(self, timeout_s=10.0):
        """SIGTERM, as a user's Ctrl+C would; returns the exit code (killed: negative)."""
        self.proc.terminate()
        try:
            return self.proc.wait(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            return self.proc.wait()
