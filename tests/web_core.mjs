// web_core.mjs - the node tests' import of runtime/web/vdsh_core.js.
// vdsh_core.js is an ES module named .js (browsers do not mind); node 18
// (Debian 12's) reads a .js outside a "type": "module" package as
// CommonJS, so it is imported from a copy named .mjs.
import { copyFileSync, mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { pathToFileURL } from 'node:url';

export async function importCore(path) {
  const dir = mkdtempSync(join(tmpdir(), 'vdsh-core-'));
  try {
    copyFileSync(path, join(dir, 'vdsh_core.mjs'));
    return await import(pathToFileURL(join(dir, 'vdsh_core.mjs')).href);
  } finally {
    rmSync(dir, { recursive: true });
  }
}
