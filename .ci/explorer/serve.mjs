// Starts `specula serve --port 0` with `args` and resolves to the server and its address.
import { spawn } from "node:child_process";

export async function startServer(binary, args = []) {
  const server = spawn(binary, ["serve", "--port", "0", ...args], { stdio: ["ignore", "pipe", "inherit"] });
  const url = await new Promise((resolve, reject) => {
    server.stdout.on("data", (chunk) => {
      const match = /on (http:\/\/\S+)/.exec(String(chunk));
      if (match) resolve(match[1]);
    });
    server.on("exit", (code) => reject(new Error(`specula serve exited with ${code}`)));
    setTimeout(() => reject(new Error("specula serve printed no address")), 20000);
  });
  return { server, url };
}

// Whether a console message counts: Chromium notes each synchronous read of a WebGL canvas
// (a check's readPixels, a 2D canvas drawing a WebGL one, a screenshot) as a driver
// "performance" warning, which says nothing about the page.
export function counts(message) {
  return !message.includes("GPU stall due to ReadPixels");
}
