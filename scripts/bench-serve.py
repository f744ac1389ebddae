#!/usr/bin/python3
"""The state stream of `uh serve` on loopback, seen by a client (docs/benchmarks.md).

Starts `uh serve --port 0`, opens and starts the default session, subscribes at each rate for a
few seconds and reports the received rate and the delivery latency of state messages (the
client's CLOCK_MONOTONIC at receipt minus the service's `clock_s` at sending, same clock on one
machine), and the round trip of `ping` for comparison.

    /usr/bin/python3 scripts/bench-serve.py [UH_BINARY] [--seconds S] [--rates 60,250,1000]

Needs Debian's python3 with python3-websockets (scripts/install-deps.sh): /usr/bin/python3, which
may not be the first python3 on PATH.
"""
import argparse
import asyncio
import json
import re
import statistics
import subprocess
import sys
import time

import websockets


def percentile(values, p):
    values = sorted(values)
    return values[min(len(values) - 1, int(round(p / 100 * (len(values) - 1))))]


async def bench(url, seconds, rates):
    async with websockets.connect(url, max_size=None) as ws:
        async def ask(**message):
            await ws.send(json.dumps(message))
            while True:
                reply = json.loads(await ws.recv())
                if reply["type"] not in ("state", "session", "contact"):
                    if reply["type"] == "error":
                        raise RuntimeError(reply["message"])
                    return reply

        await ask(type="hello", protocol=1)
        await ask(type="open")
        await ask(type="start")
        rows = []
        for rate in rates:
            await ask(type="subscribe", rate_hz=rate)
            latencies, count = [], 0
            # the first half second settles (read, not counted), then `seconds` are measured
            settle = time.monotonic() + 0.5
            while time.monotonic() < settle:
                await ws.recv()
            begin = time.monotonic()
            while time.monotonic() - begin < seconds:
                message = json.loads(await ws.recv())
                if message["type"] == "state":
                    latencies.append((time.monotonic() - message["clock_s"]) * 1e6)
                    count += 1
            elapsed = time.monotonic() - begin
            await ask(type="unsubscribe")
            rows.append((rate, count / elapsed, statistics.median(latencies), percentile(latencies, 99), max(latencies)))
        rtts = []
        for _ in range(200):
            t = time.monotonic()
            await ask(type="ping")
            rtts.append((time.monotonic() - t) * 1e6)
        report = (await ask(type="stop"))["report"]
        return rows, rtts, report


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("uh", nargs="?", default="build/release/apps/uh/uh")
    parser.add_argument("--seconds", type=float, default=3.0)
    parser.add_argument("--rates", default="60,250,1000")
    args = parser.parse_args()
    rates = [float(r) for r in args.rates.split(",")]
    server = subprocess.Popen([args.uh, "serve", "--port", "0"], stdout=subprocess.PIPE, text=True)
    try:
        line = server.stdout.readline()
        match = re.search(r"(ws://\S+/ws)", line)
        if not match:
            sys.exit(f"bench-serve: uh serve did not print its address: {line!r}")
        rows, rtts, report = asyncio.run(bench(match.group(1), args.seconds, rates))
    finally:
        server.terminate()
        server.wait(timeout=10)
    print(f"| subscribed | received | latency p50 | p99 | max |")
    print(f"|---|---|---|---|---|")
    for rate, got, p50, p99, worst in rows:
        print(f"| {rate:.0f} Hz | {got:.1f} Hz | {p50:.0f} us | {p99:.0f} us | {worst:.0f} us |")
    print(f"ping round trip: p50 {statistics.median(rtts):.0f} us, p99 {percentile(rtts, 99):.0f} us "
          f"({len(rtts)} pings)")
    print(f"session meanwhile: haptic {report['haptic']['rate_hz']:.1f} Hz, "
          f"{report['haptic']['missed_deadlines']} missed deadlines")


if __name__ == "__main__":
    main()
