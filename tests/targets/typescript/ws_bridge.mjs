#!/usr/bin/env node
// A WebSocket bridge to the virtual drone, so that the bench console can fly it from a browser.
//
//   node tests/targets/typescript/ws_bridge.mjs [--port 8765] [--drone firmware/build/host/virtual_drone]
//   (`make typescript-console` builds what it needs and runs this), then open
//   build/typescript/package/dist/console.html?bridge=ws://127.0.0.1:8765 and press "Connect bridge".
//
// It starts the virtual drone (the firmware's host build) in real time on a pseudo-terminal, holds the pty open
// like a serial port, and copies bytes between it and one WebSocket client at a time, one binary message per
// chunk. Each new client reboots the virtual board (an open of the pty does, as DTR does a real Uno's), so it
// gets the ready line. The tests import startBridge().
import { spawn } from "node:child_process";
import { closeSync, constants, createReadStream, openSync, writeSync } from "node:fs";
import { once } from "node:events";
import { createInterface } from "node:readline";
import { fileURLToPath } from "node:url";
import { WebSocketServer } from "ws";

/**
 * Starts the virtual drone and the bridge. Returns { url, outputs, sentToDrone(), close() }: `outputs` collects the
 * drone's JSON output lines (its RC pulses, laser, armed and state after every change), sentToDrone() counts the
 * bytes written to it.
 */
export async function startBridge({ executable, port = 0, host = "127.0.0.1", log = () => {} }) {
  const drone = spawn(executable, ["--clock", "realtime"], { stdio: ["ignore", "pipe", "inherit"] });
  const exited = once(drone, "exit");
  const lines = createInterface({ input: drone.stdout });
  const first = await Promise.race([
    once(lines, "line").then(([line]) => line),
    exited.then(([code]) => { throw new Error(`virtual drone exited (code ${code}) before printing its pty`); }),
  ]);
  const pty = JSON.parse(first).pty;
  if (typeof pty !== "string") throw new Error(`virtual drone: expected its pty first, got ${first}`);
  const outputs = [];
  lines.on("line", (line) => {
    try {
      outputs.push(JSON.parse(line));
    } catch {
      log(`virtual drone: ${line}`);
    }
  });

  // A blocking descriptor read through the thread pool (a tty stream on a pty slave here saw no bytes); the
  // stream closes it once the drone has exited.
  const fd = openSync(pty, constants.O_RDWR | constants.O_NOCTTY);
  const input = createReadStream(null, { fd, highWaterMark: 256 });
  let client = null;
  let written = 0;
  input.on("data", (chunk) => client?.send(chunk));
  input.on("error", () => {}); // EIO once the drone has exited
  const server = new WebSocketServer({ host, port });
  await once(server, "listening");
  server.on("connection", (socket) => {
    if (client !== null) {
      socket.close(1013, "the virtual drone has a client already");
      return;
    }
    client = socket;
    closeSync(openSync(pty, constants.O_RDWR | constants.O_NOCTTY)); // reboots the board: a fresh ready line
    socket.on("message", (data) => {
      const bytes = Buffer.isBuffer(data) ? data : Buffer.concat(Array.isArray(data) ? data : [Buffer.from(data)]);
      writeSync(fd, bytes);
      written += bytes.length;
    });
    socket.on("close", () => {
      client = null;
    });
    log(`client connected to ${pty}`);
  });

  const { port: bound } = server.address();
  return {
    url: `ws://${host}:${bound}`,
    pty,
    outputs,
    sentToDrone: () => written,
    async close() {
      for (const socket of server.clients) socket.terminate();
      await new Promise((resolve) => server.close(resolve));
      if (drone.exitCode === null) {
        drone.kill("SIGTERM");
        await exited;
      }
      input.destroy();
    },
  };
}

if (process.argv[1] === fileURLToPath(import.meta.url)) {
  const arg = (name, fallback) => {
    const i = process.argv.indexOf(name);
    return i > 0 && i + 1 < process.argv.length ? process.argv[i + 1] : fallback;
  };
  const executable = arg("--drone", process.env.DRONE_PROTOCOL_VIRTUAL_DRONE ?? "firmware/build/host/virtual_drone");
  const bridge = await startBridge({ executable, port: Number(arg("--port", "8765")), log: console.log });
  console.log(`bridge ${bridge.url} -> virtual drone on ${bridge.pty}`);
  console.log(`open build/typescript/package/dist/console.html?bridge=${bridge.url} and press "Connect bridge"; Ctrl-C stops`);
  for (const signal of ["SIGINT", "SIGTERM"]) process.once(signal, () => void bridge.close().then(() => process.exit(0)));
}
