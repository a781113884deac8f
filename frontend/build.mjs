// Bundles every entry point src/<name>/main.ts into dist/hrc/<name>.js (with
// its CSS beside it), which Django serves as static "hrc/<name>.js", and each
// page stylesheet src/pages/<name>.css into dist/hrc/pages/<name>.css (the
// Content-Security-Policy admits no inline <style>, so the templates link these).
import { build } from "esbuild";
import { readdirSync, existsSync } from "node:fs";

const entryPoints = Object.fromEntries([
  ...readdirSync("src", { withFileTypes: true })
    .filter((entry) => entry.isDirectory() && existsSync(`src/${entry.name}/main.ts`))
    .map((entry) => [entry.name, `src/${entry.name}/main.ts`]),
  ...readdirSync("src/pages")
    .filter((name) => name.endsWith(".css"))
    .map((name) => [`pages/${name.slice(0, -".css".length)}`, `src/pages/${name}`]),
]);

await build({
  entryPoints,
  outdir: "dist/hrc",
  bundle: true,
  minify: true,
  sourcemap: true,
  format: "esm",
  target: "es2020",
  loader: { ".svg": "text" },
  logLevel: "warning",
});
console.log(`built ${Object.keys(entryPoints).join(", ") || "nothing"} into dist/hrc/`);
