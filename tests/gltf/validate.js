// Validates glTF/GLB files with the Khronos glTF Validator (npm package
// `gltf-validator`, the official validator compiled to JavaScript).
//
//   NODE_PATH=path/to/node_modules node tests/gltf/validate.js FILE... [--report OUT.json]
//
// Prints one line per file (errors, warnings, infos, and the first messages)
// and exits 1 when any file has an error. Warnings are printed, not failed:
// the issue asks for "no errors".
"use strict";
const fs = require("fs");
const path = require("path");
const validator = require("gltf-validator");

async function validate(file) {
    const bytes = new Uint8Array(fs.readFileSync(file));
    const report = await validator.validateBytes(bytes, {
        uri: path.basename(file),
        maxIssues: 100,
        // A .gltf that points at a .bin beside it.
        externalResourceFunction: (uri) =>
            new Promise((resolve, reject) => {
                const full = path.resolve(path.dirname(file), decodeURIComponent(uri));
                fs.readFile(full, (err, data) => (err ? reject(err.toString()) : resolve(data)));
            }),
    });
    return report;
}

async function main() {
    const args = process.argv.slice(2);
    let reportPath = null;
    const files = [];
    for (let i = 0; i < args.length; i++) {
        if (args[i] === "--report") reportPath = args[++i];
        else files.push(args[i]);
    }
    if (files.length === 0) {
        console.error("usage: validate.js FILE... [--report OUT.json]");
        process.exit(2);
    }
    const results = [];
    let failed = 0;
    for (const file of files) {
        let line;
        try {
            const report = await validate(file);
            const issues = report.issues;
            const first = issues.messages
                .slice(0, 5)
                .map((m) => `${["error", "warning", "info", "hint"][m.severity]} ${m.code} at ${m.pointer || ""}: ${m.message}`);
            results.push({
                file,
                errors: issues.numErrors,
                warnings: issues.numWarnings,
                infos: issues.numInfos,
                messages: issues.messages,
                info: report.info,
            });
            if (issues.numErrors > 0) failed++;
            line = `GLTF-VALIDATOR ${file}: ${issues.numErrors} errors, ${issues.numWarnings} warnings, ${issues.numInfos} infos`;
            if (first.length) line += "\n  " + first.join("\n  ");
        } catch (e) {
            failed++;
            results.push({ file, errors: 1, exception: String(e) });
            line = `GLTF-VALIDATOR ${file}: the validator could not read it: ${e}`;
        }
        console.log(line);
    }
    if (reportPath) {
        fs.writeFileSync(reportPath, JSON.stringify({ validator: validator.version(), results }, null, 1));
    }
    console.log(`GLTF-VALIDATOR ${files.length - failed} of ${files.length} files without errors (validator ${validator.version()})`);
    process.exit(failed ? 1 : 0);
}

main();
