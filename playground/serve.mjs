#!/usr/bin/env node
// Serves the built playground (`cargo xtask playground` writes it to target/playground) as
// static files: `node playground/serve.mjs DIR [HOST:PORT]` (127.0.0.1:8080 by default).
// The browser test (test.mjs) imports `serve` to run the same server on a free port.
import { createServer } from 'node:http';
import { readFile } from 'node:fs/promises';
import { extname, join, normalize, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';

const TYPES = { '.html': 'text/html; charset=utf-8', '.js': 'text/javascript', '.css': 'text/css', '.json': 'application/json', '.wasm': 'application/wasm', '.png': 'image/png', '.svg': 'image/svg+xml', '.uf2': 'application/octet-stream' };

/** Serves `dir` at `host:port` (port 0: any free one); resolves to the server once it listens. */
export function serve(dir, host = '127.0.0.1', port = 8080) {
  const root = resolve(dir);
  const server = createServer(async (req, res) => {
    // Whatever a browser or a neighbour on the network sends, the server answers and goes on:
    // a path that does not decode (`/%E0%A4%A`) or holds a NUL byte is a bad request.
    let path;
    try {
      path = normalize(decodeURIComponent(new URL(req.url, 'http://x').pathname));
    } catch {
      path = null;
    }
    if (path === null || path.includes('\0')) {
      res.writeHead(400, { 'content-type': 'text/plain' }).end('bad request: the path does not decode\n');
      return;
    }
    if (req.method !== 'GET' && req.method !== 'HEAD') {
      res.writeHead(405, { 'content-type': 'text/plain', allow: 'GET, HEAD' }).end('only GET and HEAD\n');
      return;
    }
    const file = join(root, path.endsWith('/') ? join(path, 'index.html') : path);
    if (!file.startsWith(root)) {
      res.writeHead(403).end();
      return;
    }
    try {
      const body = await readFile(file);
      res.writeHead(200, { 'content-type': TYPES[extname(file)] ?? 'application/octet-stream', 'cache-control': 'no-store' }).end(body);
    } catch {
      res.writeHead(404, { 'content-type': 'text/plain' }).end(`${path}: not found\n`);
    }
  });
  return new Promise((ok, fail) => {
    server.once('error', fail);
    server.listen(port, host, () => ok(server));
  });
}

if (process.argv[1] && resolve(process.argv[1]) === fileURLToPath(import.meta.url)) {
  const [dir, addr = '127.0.0.1:8080'] = process.argv.slice(2);
  if (!dir) {
    console.error('usage: node playground/serve.mjs DIR [HOST:PORT]');
    process.exit(2);
  }
  const [host, port] = addr.includes(':') ? [addr.slice(0, addr.lastIndexOf(':')), Number(addr.slice(addr.lastIndexOf(':') + 1))] : ['127.0.0.1', Number(addr)];
  serve(dir, host, port).then(
    (s) => console.log(`serving ${resolve(dir)} at http://${host}:${s.address().port}/ (Ctrl-C stops)`),
    (e) => {
      console.error(`cannot serve at ${addr}: ${e.message}`);
      process.exit(1);
    },
  );
}
