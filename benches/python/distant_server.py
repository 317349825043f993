"""A file server on loopback that answers as a distant one does (benches/remote_latency.sh):
each request waits LATENCY_MS before its answer starts (a round trip to a bucket in another
building or region), and each connection's bytes are paced to STREAM_MBPS (what one connection
to a cloud bucket carries, ~100 MB/s). HTTP/1.1 with keep-alive: HEAD, and GET whole or with
`Range: bytes=a-b` (206 and Content-Range); the files of one folder, held in memory once read.

    LATENCY_MS=20 STREAM_MBPS=100 python distant_server.py FOLDER   # prints its port
"""
import asyncio
import os
import pathlib
import sys

LATENCY_S = float(os.environ.get("LATENCY_MS", "20")) / 1e3
STREAM_BPS = float(os.environ.get("STREAM_MBPS", "100")) * 1e6
ROOT = pathlib.Path(sys.argv[1])
FILES = {}
SLICE = 1 << 18


def body_of(name):
    if name not in FILES:
        path = ROOT / name
        FILES[name] = path.read_bytes() if path.is_file() else None
    return FILES[name]


async def answer(reader, writer):
    try:
        while True:
            line = await reader.readline()
            if not line:
                break
            method, target, _ = line.decode().split(" ", 2)
            headers = {}
            while True:
                h = await reader.readline()
                if h in (b"\r\n", b"\n", b""):
                    break
                key, value = h.decode().split(":", 1)
                headers[key.strip().lower()] = value.strip()
            data = body_of(target.lstrip("/").split("?")[0])
            await asyncio.sleep(LATENCY_S)
            if data is None:
                writer.write(b"HTTP/1.1 404 Not Found\r\nContent-Length: 0\r\n\r\n")
                await writer.drain()
                continue
            start, end, status, extra = 0, len(data), "200 OK", ""
            asked = headers.get("range", "")
            if asked.startswith("bytes="):
                a, b = asked[6:].split("-")
                start = int(a)
                end = min(int(b) + 1, len(data)) if b else len(data)
                status = "206 Partial Content"
                extra = f"Content-Range: bytes {start}-{end - 1}/{len(data)}\r\n"
            writer.write(f"HTTP/1.1 {status}\r\nContent-Length: {end - start}\r\n"
                         f"ETag: \"1\"\r\n{extra}\r\n".encode())
            if method == "GET":
                for at in range(start, end, SLICE):
                    part = data[at:min(end, at + SLICE)]
                    writer.write(part)
                    await asyncio.sleep(len(part) / STREAM_BPS)
                    await writer.drain()
            await writer.drain()
    except (ConnectionError, ValueError):
        pass
    finally:
        writer.close()


async def main():
    server = await asyncio.start_server(answer, "127.0.0.1", 0)
    print(server.sockets[0].getsockname()[1], flush=True)
    async with server:
        await server.serve_forever()


asyncio.run(main())
