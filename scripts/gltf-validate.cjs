// Khronos' glTF validator (the npm package gltf-validator) on plume's .glb files:
//   node scripts/gltf-validate.cjs FILE.glb...
// prints per file "FILE: N errors, N warnings, N infos" and the first messages; exits 1 when a
// file has errors (warnings are printed, not failed), 2 when the validator is not installed.
// The package is looked up in $PLUME_GLTF_VALIDATOR (a node_modules folder), then in
// build/tools/node_modules (scripts/install-deps.sh --graphics puts it there), then Node's own path.
"use strict";
const fs = require("fs");
const path = require("path");

function loadValidator() {
    const places = [process.env.PLUME_GLTF_VALIDATOR, path.join(__dirname, "..", "build", "tools", "node_modules")];
    for (const p of places) {
        if (p && fs.existsSync(path.join(p, "gltf-validator")))
            return require(path.join(p, "gltf-validator"));
    }
    try {
        return require("gltf-validator");
    } catch (e) {
        console.error("gltf-validate: the npm package gltf-validator is not installed " +
                      "(scripts/install-deps.sh --graphics installs it into build/tools)");
        process.exit(2);
    }
}

async function main() {
    const files = process.argv.slice(2);
    if (files.length === 0) {
        console.error("usage: node scripts/gltf-validate.cjs FILE.glb...");
        process.exit(2);
    }
    const validator = loadValidator();
    let failed = 0;
    for (const f of files) {
        let bytes;
        try {
            bytes = new Uint8Array(fs.readFileSync(f));
        } catch (e) {
            console.error(`gltf-validate: ${f}: ${e.message}`);
            failed++;
            continue;
        }
        const report = await validator.validateBytes(bytes, {maxIssues: 100});
        const i = report.issues;
        console.log(`${f}: ${i.numErrors} errors, ${i.numWarnings} warnings, ${i.numInfos} infos ` +
                    `(validator ${report.validatorVersion})`);
        for (const m of i.messages.slice(0, 10))
            console.log(`  ${["error", "warning", "info", "hint"][m.severity] || m.severity} ${m.code} ${m.pointer || ""}: ${m.message}`);
        if (i.numErrors > 0)
            failed++;
    }
    process.exit(failed ? 1 : 0);
}

main();
