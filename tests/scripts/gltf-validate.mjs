// Validate a `timpanist render --glb` file with the Khronos glTF validator (npm package
// `gltf-validator`): prints the counts of errors, warnings and infos with the first
// messages, and exits 1 on any error or warning.
// Usage: npm install gltf-validator; node tests/scripts/gltf-validate.mjs OUT.glb
import validator from 'gltf-validator';
import fs from 'fs';

const bytes = new Uint8Array(fs.readFileSync(process.argv[2]));
const report = await validator.validateBytes(bytes);
const { numErrors, numWarnings, numInfos, messages } = report.issues;
console.log(`${process.argv[2]}: ${numErrors} errors, ${numWarnings} warnings, ${numInfos} infos; ` +
    `${report.info.animationCount} animation, ${report.info.drawCallCount} draw calls, ` +
    `${report.info.totalTriangleCount} triangles`);
for (const m of messages.slice(0, 20)) console.log(`  ${m.code} ${m.pointer ?? ''}: ${m.message}`);
process.exit(numErrors + numWarnings > 0 ? 1 : 0);
