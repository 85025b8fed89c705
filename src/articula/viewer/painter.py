"""The live page's updates on a thread of their own: the control loop hands over its newest
picture and goes on; it never waits on the browser.

Pushing a picture to viser takes about 2 ms, and far longer now and then (its message
buffer's lock, the websocket's event loop, a browser rendering on the same cores): measured
in the control loop it made 1-3 % of 10 ms periods late. Here a slow push only delays, or
drops, a picture; the newest one always wins.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable

import viser


class Painter:
    """Runs `paint` callables in one `server.atomic()` batch each, newest first, on a thread.

    Args:
        server: the viser server the pictures are pushed to.
    """

    def __init__(self, server: viser.ViserServer) -> None:
        self._server = server
        self._pending: Callable[[], None] | None = None
        self._lock = threading.Lock()
        self._wake = threading.Event()
        self._idle = threading.Event()
        self._idle.set()
        self._stopped = False
        self.paint_ms: list[float] = []  # wall time of each picture pushed [ms]
        self._thread = threading.Thread(target=self._run, name="articula-painter", daemon=True)
        self._thread.start()

    def post(self, paint: Callable[[], None]) -> None:
        """Hand over the newest picture; one handed over before and not yet painted is
        dropped.

        Args:
            paint: updates the page's scene and panel (run on the painter's thread).
        """
        with self._lock:
            self._pending = paint
            self._idle.clear()
        self._wake.set()

    def flush(self, timeout: float = 5.0) -> bool:
        """Wait up to `timeout` until every picture handed over is on its way to the page.

        Args:
            timeout: the longest wait [s].

        Returns:
            Whether every picture handed over was painted in time.
        """
        return self._idle.wait(timeout)

    def stop(self) -> None:
        """Paint what is pending, then end the thread."""
        self._stopped = True
        self._wake.set()
        self._thread.join(timeout=5.0)

    def _run(self) -> None:
        """Paint whatever is newest each time something is handed over, until stopped."""
        while True:
            self._wake.wait()
            self._wake.clear()
            with self._lock:
                paint, self._pending = self._pending, None
            if paint is not None:
                start = time.perf_counter()
                with self._server.atomic():
                    paint()
                self.paint_ms.append(1e3 * (time.perf_counter() - start))
            with self._lock:
                if self._pending is None:
                    self._idle.set()
            if self._stopped:
                return
