// The one Node API the editor's tests use (the examples are read from the repository);
// the project's TypeScript setup has no Node typings.
declare module "node:fs" {
  export function readFileSync(path: URL, encoding: "utf-8"): string;
}
