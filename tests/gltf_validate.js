// gltf_validate.js NODE_MODULES FILE.glb... - the Khronos glTF Validator
// (npm gltf-validator) on each file: prints its issue counts and every
// error and warning; exit 1 when any file has an error (or cannot be read).
const path = require('path');
const fs = require('fs');
const validator = require(path.join(process.argv[2], 'gltf-validator'));
(async () => {
  let bad = 0;
  for (const f of process.argv.slice(3)) {
    try {
      const r = await validator.validateBytes(new Uint8Array(fs.readFileSync(f)), {maxIssues: 100});
      const i = r.issues;
      console.log(`${f}: ${i.numErrors} errors, ${i.numWarnings} warnings, ${i.numInfos} infos, ${i.numHints} hints`);
      for (const m of i.messages)
        if (m.severity <= 1) console.log(`  ${m.severity === 0 ? 'error' : 'warning'} ${m.code} ${m.pointer || ''}: ${m.message}`);
      if (i.numErrors > 0) bad++;
    } catch (e) {
      console.log(`${f}: validator failed: ${e}`);
      bad++;
    }
  }
  process.exit(bad ? 1 : 0);
})();
