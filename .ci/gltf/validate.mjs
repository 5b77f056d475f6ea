// Validates glTF files with the Khronos glTF validator; exits 1 when any has an error.
//   node .ci/gltf/validate.mjs FILE.glb...
import { readFileSync } from 'node:fs';
import validator from 'gltf-validator';

let failed = false;
for (const file of process.argv.slice(2)) {
  const report = await validator.validateBytes(new Uint8Array(readFileSync(file)), { maxIssues: 20 });
  const { numErrors, numWarnings, messages } = report.issues;
  console.log(`${file}: ${numErrors} errors, ${numWarnings} warnings`);
  for (const m of messages.slice(0, 20)) console.log(`  ${m.code} ${m.message} (${m.pointer ?? ''})`);
  if (numErrors > 0) failed = true;
}
process.exit(failed ? 1 : 0);
