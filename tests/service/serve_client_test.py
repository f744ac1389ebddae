"""`uh serve` as a script sees it (Debian's python3-websockets): the client flow of docs/cli.md on the
default scene, an error that leaves the connection usable, and the controller's disconnect
stopping the session for a watcher. Then `uh run --view`: a watcher sees its session, may not stop
it, and the program ends with its report.

    python3 serve_client_test.py UH_BINARY
"""
import asyncio
import json
import re
import subprocess
import sys

import websockets

failures = []


def check(condition, what):
    print(("ok   " if condition else "FAIL ") + what)
    if not condition:
        failures.append(what)


async def next_of(ws, kind):
    while True:
        m = json.loads(await asyncio.wait_for(ws.recv(), 60))
        if m["type"] == kind:
            return m


async def run(url):
    async with websockets.connect(url) as watcher:
        await watcher.send(json.dumps({"type": "hello", "protocol": 1}))
        await next_of(watcher, "welcome")
        await watcher.send(json.dumps({"type": "subscribe", "rate_hz": 20}))
        await next_of(watcher, "subscribed")
        async with websockets.connect(url) as ws:
            for m in ({"type": "hello", "protocol": 1}, {"type": "open"}, {"type": "start", "id": "s"}):
                await ws.send(json.dumps(m))
            started = await next_of(ws, "started")
            check(started.get("id") == "s", "start is answered with its id once the session runs")
            await ws.send("{not json")
            error = await next_of(ws, "error")
            check("not valid JSON" in error["message"], f"malformed JSON is named: {error['message'][:60]}")
            states = [await next_of(watcher, "state") for _ in range(10)]
            positions = {tuple(s["tool"]["position"]) for s in states}
            check(len(positions) > 1, f"the watcher sees the tool move ({len(positions)} positions in 10 states)")
            check(all(len(s["force"]) == 3 for s in states), "states carry the force")
        # the controlling client is gone: its session stops and closes
        while True:
            m = await next_of(watcher, "session")
            if m["status"] == "closed":
                break
        check(True, "the controller's disconnect stops and closes its session")


async def watch_run(url):
    async with websockets.connect(url) as ws:
        await ws.send(json.dumps({"type": "hello", "protocol": 1}))
        welcome = await next_of(ws, "welcome")
        check((welcome["session"] or {}).get("status") == "running", f"uh run --view: its session is running ({welcome['session']})")
        await ws.send(json.dumps({"type": "subscribe", "rate_hz": 50}))
        state = await next_of(ws, "state")
        check(len(state["tool"]["position"]) == 3, "uh run --view: a browser's socket gets states")
        await ws.send(json.dumps({"type": "stop"}))
        error = await next_of(ws, "error")
        check("belongs to the program" in error["message"], "uh run --view: a watcher may not stop it")


def run_with_view(uh):
    run = subprocess.Popen([uh, "run", "--view", "--port", "0", "--seconds", "3", "--no-realtime", "--json"],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    line = ""
    while "live view:" not in line:
        line = run.stderr.readline()
        if not line:
            break
    match = re.search(r"live view: http://(\S+)/", line)
    check(match is not None, "uh run --view prints the view's address")
    if match:
        asyncio.run(watch_run(f"ws://{match.group(1)}/ws"))
    out, _ = run.communicate(timeout=120)
    check(run.returncode == 0, f"uh run --view ends by itself (exit {run.returncode})")
    report = json.loads(out) if run.returncode == 0 else {}
    check(report.get("haptic", {}).get("ticks", 0) > 0, "uh run --view prints its report")


def main():
    server = subprocess.Popen([sys.argv[1], "serve", "--port", "0", "--no-realtime"], stdout=subprocess.PIPE, text=True)
    try:
        match = re.search(r"(ws://\S+/ws)", server.stdout.readline())
        check(match is not None, "uh serve prints its address")
        if match:
            asyncio.run(run(match.group(1)))
    finally:
        server.terminate()
        check(server.wait(timeout=30) == 0, "uh serve stops cleanly on SIGTERM")
    run_with_view(sys.argv[1])
    print(f"python client test: {'passed' if not failures else f'{len(failures)} failed'}")
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
