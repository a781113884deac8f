// Bundles every entry point src/<name>/main.ts into dist/hrc/<name>.js (with
// its CSS beside it), which Django serves as static "hrc/<name>.js".
import { build } from "esbuild";
import { readdirSync, existsSync } from "node:fs";

const entryPoints = Object.fromEntries(
  readdirSync("src", { withFileTypes: true })
    .filter((entry) => entry.isDirectory() && existsSync(`src/${entry.name}/main.ts`))
    .map((entry) => [entry.name, `src/${entry.name}/main.ts`]),
);

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
