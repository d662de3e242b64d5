// Static file server for www/ with the right MIME types (application/wasm for .wasm).
// Usage: node scripts/serve.mjs [--port 8080] [--host 127.0.0.1] [--root www]
// Prints the URL it serves on; --port 0 picks a free port.
import { createServer } from 'node:http';
import { readFile, stat } from 'node:fs/promises';
import { basename, extname, join, normalize, resolve, sep } from 'node:path';
import { fileURLToPath } from 'node:url';

const here = fileURLToPath(new URL('.', import.meta.url));
const args = process.argv.slice(2);
const opt = (name, dflt) => {
  const i = args.indexOf(name);
  return i >= 0 && i + 1 < args.length ? args[i + 1] : dflt;
};
const port = Number(opt('--port', '8080'));
const host = opt('--host', '127.0.0.1');
const root = resolve(opt('--root', join(here, '..', 'www')));

const TYPES = {
  '.html': 'text/html; charset=utf-8',
  '.js': 'text/javascript; charset=utf-8',
  '.mjs': 'text/javascript; charset=utf-8',
  '.css': 'text/css; charset=utf-8',
  '.json': 'application/json',
  '.wasm': 'application/wasm',
  '.svg': 'image/svg+xml',
  '.png': 'image/png',
  '.ico': 'image/x-icon',
  '.tsm': 'text/plain; charset=utf-8',
  '.obj': 'text/plain; charset=utf-8',
  '.ts': 'text/plain; charset=utf-8',
  '.md': 'text/plain; charset=utf-8',
};
/** Licence texts without an extension of their own (`LICENSE.LGPL-3.0`), shown as text. */
const TEXT_NAMES = /^(LICENSE|COPYING)(\.|$)/;

export function startServer(listenPort = port, listenHost = host) {
  const server = createServer(async (req, res) => {
    try {
      const url = new URL(req.url, 'http://localhost');
      let path = normalize(decodeURIComponent(url.pathname));
      if (path.endsWith('/')) path += 'index.html';
      const file = resolve(join(root, path));
      if (file !== root && !file.startsWith(root + sep)) {
        res.writeHead(403).end('forbidden');
        return;
      }
      const info = await stat(file);
      if (!info.isFile()) throw new Error('not a file');
      const body = await readFile(file);
      res.writeHead(200, {
        'Content-Type': TYPES[extname(file)]
          || (TEXT_NAMES.test(basename(file)) ? 'text/plain; charset=utf-8' : 'application/octet-stream'),
        'Cache-Control': 'no-store',
      });
      res.end(body);
    } catch {
      res.writeHead(404, { 'Content-Type': 'text/plain' }).end('not found');
    }
  });
  return new Promise((ok) => {
    server.listen(listenPort, listenHost, () => {
      const { port: p } = server.address();
      ok({ server, url: `http://${listenHost}:${p}/` });
    });
  });
}

if (process.argv[1] && resolve(process.argv[1]) === fileURLToPath(import.meta.url)) {
  const { url } = await startServer();
  console.log(`tspath is served at ${url}  (Ctrl-C stops)`);
}
