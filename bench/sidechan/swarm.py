"""A crowd of hostile and careless live-view clients, in its own process (its own interpreter lock).

``python -m bench.sidechan.swarm URL --viewers N --idle N --slow N --reset N --seconds S [--nice N]`` keeps that
many clients of each kind going until the time is up (or SIGTERM), reconnecting each one the server closes, and
prints one JSON object: connections made, frames (MJPEG parts) read, refusals, the latency of ``state.json``
polled once every 200 ms by one well-behaved client (the page's own poll, which must stay reachable), and the
swarm's own processor time (what the crowd took from the machine).

* viewer: reads ``stream.mjpg`` as fast as it comes;
* idle: connects and never sends a byte;
* slow: asks for the stream and reads 100 bytes a second;
* reset: sends a request and resets the connection at once (SO_LINGER 0).
"""

from __future__ import annotations

import argparse
import asyncio
import json
import os
import resource
import signal
import socket
import struct
import time
from collections import Counter
from collections.abc import AsyncIterator, Sequence
from urllib.parse import urlsplit


class Swarm:
    def __init__(self, url: str, seconds: float) -> None:
        parts = urlsplit(url)
        self.host, self.port, self.path = parts.hostname or "127.0.0.1", parts.port or 80, parts.path
        self.deadline = time.monotonic() + seconds
        self.counts: Counter[str] = Counter()
        self.state_ms: list[float] = []

    def alive(self) -> bool:
        return time.monotonic() < self.deadline

    def stop(self) -> None:
        self.deadline = time.monotonic()

    async def connections(self) -> AsyncIterator[tuple[asyncio.StreamReader, asyncio.StreamWriter]]:
        """A new connection each time round, until the time is up."""
        while self.alive():
            try:
                reader, writer = await asyncio.open_connection(self.host, self.port)
            except OSError:
                self.counts["connect failed"] += 1
                await asyncio.sleep(0.2)
                continue
            self.counts["connections"] += 1
            yield reader, writer

    def _get(self, writer: asyncio.StreamWriter, route: str) -> None:
        writer.write(f"GET {self.path}{route} HTTP/1.1\r\nHost: {self.host}\r\n\r\n".encode())

    async def viewer(self, rate: int | None) -> None:
        async for reader, writer in self.connections():
            try:
                self._get(writer, "stream.mjpg")
                status = await reader.readline()
                if b" 503 " in status:
                    self.counts["stream refused (503)"] += 1
                while self.alive():
                    data = await reader.read(rate or 65536)
                    if not data:
                        break
                    self.counts["parts read"] += data.count(b"--liveviewframe")
                    if rate:
                        await asyncio.sleep(1.0)
            except OSError:
                self.counts["reset by server"] += 1
            finally:
                writer.close()
            await asyncio.sleep(0.2)

    async def idle(self) -> None:
        async for reader, writer in self.connections():
            try:
                while self.alive() and await reader.read(1024):
                    pass
            except OSError:
                pass
            finally:
                writer.close()
            self.counts["idle closed by server"] += 1

    async def reset(self) -> None:
        async for _, writer in self.connections():
            self._get(writer, "state.json")
            await writer.drain()
            sock = writer.get_extra_info("socket")
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
            writer.transport.abort()
            self.counts["resets"] += 1
            await asyncio.sleep(0.05)

    async def poll_state(self) -> None:
        t0 = time.monotonic()
        async for reader, writer in self.connections():
            try:
                self._get(writer, "state.json")
                body = await asyncio.wait_for(reader.read(), timeout=5)
                if b" 200 " in body.split(b"\r\n", 1)[0]:
                    self.state_ms.append((time.monotonic() - t0) * 1000)
                else:
                    self.counts["state.json failed"] += 1
            except (OSError, TimeoutError):
                self.counts["state.json failed"] += 1
            finally:
                writer.close()
            await asyncio.sleep(0.2)
            t0 = time.monotonic()


async def _run(args: argparse.Namespace) -> dict[str, object]:
    swarm = Swarm(args.url, args.seconds)
    tasks = [swarm.viewer(None) for _ in range(args.viewers)]
    tasks += [swarm.idle() for _ in range(args.idle)]
    tasks += [swarm.viewer(100) for _ in range(args.slow)]
    tasks += [swarm.reset() for _ in range(args.reset)]
    tasks.append(swarm.poll_state())
    running = [asyncio.ensure_future(t) for t in tasks]
    stopped = asyncio.Event()
    asyncio.get_running_loop().add_signal_handler(signal.SIGTERM, stopped.set)
    everyone: asyncio.Future[object] = asyncio.ensure_future(asyncio.gather(*running, return_exceptions=True))
    waiter: asyncio.Future[object] = asyncio.ensure_future(stopped.wait())
    await asyncio.wait([everyone, waiter], timeout=args.seconds + 1.0, return_when=asyncio.FIRST_COMPLETED)
    swarm.stop()  # a client stuck in a connect or a read is cut off
    waiter.cancel()
    for task in running:
        task.cancel()
    await asyncio.gather(*running, return_exceptions=True)
    ms = sorted(swarm.state_ms)
    use = resource.getrusage(resource.RUSAGE_SELF)
    return {**swarm.counts, "state polls": len(ms),
            "state p50 ms": round(ms[len(ms) // 2], 1) if ms else None,
            "state max ms": round(ms[-1], 1) if ms else None,
            "cpu_s": round(use.ru_utime + use.ru_stime, 2), "rss_mb": round(use.ru_maxrss / 1024, 1)}


def main(argv: Sequence[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="swarm")
    p.add_argument("url")
    for kind in ("viewers", "idle", "slow", "reset"):
        p.add_argument(f"--{kind}", type=int, default=0)
    p.add_argument("--seconds", type=float, default=10.0)
    p.add_argument("--nice", type=int, default=0, help="lower the swarm's priority by this much")
    args = p.parse_args(argv)
    if args.nice:
        os.nice(args.nice)
    print(json.dumps(asyncio.run(_run(args))), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
