#!/usr/bin/env python3
"""A relay that adds a fixed round trip to TCP or UDP traffic: each chunk (or datagram) is
held for half the round trip in each direction, in order. This kernel has no `tc netem`, so
the harness puts this relay in front of a `tbf`-shaped link to make a long link.

    relay.py tcp LISTEN_HOST LISTEN_PORT TARGET_HOST TARGET_PORT RTT_MS LIFETIME_S
    relay.py udp LISTEN_HOST LISTEN_PORT TARGET_HOST TARGET_PORT RTT_MS LIFETIME_S

It runs inside the harness's client namespace and exits by itself after LIFETIME_S seconds.
Reads stop while a direction holds more than MAX_HELD bytes (backpressure, not unbounded
memory); the relay itself never adds a queue beyond the delay.
"""

import asyncio
import sys
import time

MAX_HELD = 8 << 20
CHUNK = 65536


async def pump(reader, writer, delay):
    """Copies reader to writer, each chunk `delay` seconds after it was read."""
    held = asyncio.Queue()
    size = [0]
    room = asyncio.Event()
    room.set()

    async def deliver():
        while True:
            due, data = await held.get()
            if data is None:
                break
            wait = due - time.monotonic()
            if wait > 0:
                await asyncio.sleep(wait)
            writer.write(data)
            await writer.drain()
            size[0] -= len(data)
            if size[0] <= MAX_HELD:
                room.set()
        writer.close()

    delivering = asyncio.ensure_future(deliver())
    try:
        while True:
            await room.wait()
            data = await reader.read(CHUNK)
            if not data:
                break
            size[0] += len(data)
            if size[0] > MAX_HELD:
                room.clear()
            held.put_nowait((time.monotonic() + delay, data))
    except (ConnectionError, OSError):
        pass
    held.put_nowait((0.0, None))
    try:
        await delivering
    except (ConnectionError, OSError):
        pass


async def tcp(listen_host, listen_port, target_host, target_port, one_way):
    async def connection(client_reader, client_writer):
        try:
            server_reader, server_writer = await asyncio.open_connection(target_host, target_port)
        except OSError:
            client_writer.close()
            return
        await asyncio.gather(
            pump(client_reader, server_writer, one_way),
            pump(server_reader, client_writer, one_way),
        )

    server = await asyncio.start_server(connection, listen_host, listen_port)
    print("listening", flush=True)
    async with server:
        await server.serve_forever()


class Udp(asyncio.DatagramProtocol):
    """One side of the UDP relay; `send` delivers to the other side after the delay."""

    def __init__(self, one_way):
        self.one_way = one_way
        self.transport = None
        self.peer = None
        self.on_datagram = None

    def connection_made(self, transport):
        self.transport = transport

    def datagram_received(self, data, addr):
        self.peer = self.peer or addr
        if self.on_datagram:
            self.on_datagram(data, addr)

    def later(self, data, addr):
        loop = asyncio.get_running_loop()
        loop.call_later(self.one_way, lambda: self.transport and self.transport.sendto(data, addr))


async def udp(listen_host, listen_port, target_host, target_port, one_way):
    loop = asyncio.get_running_loop()
    _, near = await loop.create_datagram_endpoint(lambda: Udp(one_way), local_addr=(listen_host, listen_port))
    _, far = await loop.create_datagram_endpoint(lambda: Udp(one_way), remote_addr=(target_host, target_port))
    client = {}

    def from_client(data, addr):
        client["addr"] = addr
        far.later(data, None)

    def from_server(data, _addr):
        if "addr" in client:
            near.later(data, client["addr"])

    near.on_datagram = from_client
    far.on_datagram = from_server
    print("listening", flush=True)
    await asyncio.Event().wait()


def main():
    if len(sys.argv) != 8 or sys.argv[1] not in ("tcp", "udp"):
        print(__doc__.strip().splitlines()[3], file=sys.stderr)
        sys.exit(2)
    kind, listen_host, listen_port, target_host, target_port, rtt_ms, lifetime = sys.argv[1:]
    one_way = float(rtt_ms) / 2000.0
    run = tcp if kind == "tcp" else udp
    coroutine = run(listen_host, int(listen_port), target_host, int(target_port), one_way)
    try:
        asyncio.run(asyncio.wait_for(coroutine, timeout=float(lifetime)))
    except asyncio.TimeoutError:
        pass


if __name__ == "__main__":
    main()
