// tests/test_engines.c's validator: node validate.mjs NODE_MODULES FILE.gltf runs the Khronos glTF
// validator over the file and the files it names, prints the counts and every error and warning, and
// exits 1 when there is an error (2 when the validator itself could not run).
import fs from 'fs';
import path from 'path';
import { createRequire } from 'module';

const [modules, file] = process.argv.slice(2);
const validator = createRequire(path.join(path.resolve(modules), 'index.js'))('gltf-validator');
const external = (uri) => new Promise((resolve, reject) => {
    try {
        resolve(new Uint8Array(fs.readFileSync(path.resolve(path.dirname(file), decodeURIComponent(uri)))));
    } catch (e) {
        reject(e.toString());
    }
});
try {
    const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)),
                                                 { uri: file, maxIssues: 1000, externalResourceFunction: external });
    const issues = report.issues;
    console.log(`${file}: ${issues.numErrors} errors, ${issues.numWarnings} warnings, ${issues.numInfos} infos`);
    for (const m of issues.messages)
        if (m.severity <= 1)
            console.log(`  ${m.severity ? 'warning' : 'error'} ${m.code} at ${m.pointer}: ${m.message}`);
    process.exit(issues.numErrors ? 1 : 0);
} catch (e) {
    console.log(`${file}: the validator failed: ${e}`);
    process.exit(2);
}
