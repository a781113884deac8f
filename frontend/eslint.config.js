// ESLint for the frontend: typescript-eslint's recommended rules with type information
// (`npm run lint`, and `make lint`). Every rule turned off says why.
import js from "@eslint/js";
import { defineConfig } from "eslint/config";
import tseslint from "typescript-eslint";

const UNSAFE_ANY_RULES = {
  "@typescript-eslint/no-unsafe-argument": "off",
  "@typescript-eslint/no-unsafe-assignment": "off",
  "@typescript-eslint/no-unsafe-call": "off",
  "@typescript-eslint/no-unsafe-member-access": "off",
  "@typescript-eslint/no-unsafe-return": "off",
};

export default defineConfig(
  { ignores: ["dist/", "node_modules/"] },
  { linterOptions: { reportUnusedDisableDirectives: "error" } },
  js.configs.recommended,
  tseslint.configs.recommendedTypeChecked,
  {
    languageOptions: {
      parserOptions: {
        // The build script, the Node tools and the configs sit outside tsconfig.json's src/ and test/.
        projectService: { allowDefaultProject: ["*.js", "*.mjs", "vitest.config.ts", "test/live/*.mjs"] },
        tsconfigRootDir: import.meta.dirname,
      },
    },
    rules: {
      // `{ lanes: _lanes, ...rest }` is how the code leaves a key out of a copy.
      "@typescript-eslint/no-unused-vars": ["error", { ignoreRestSiblings: true }],
      // String() of a value read from a pattern document or an API answer is the text the page
      // shows; where a text belongs the server's checks refuse an object, so "[object Object]"
      // cannot reach the page, and a helper at each of the many reads would only hide String().
      "@typescript-eslint/no-base-to-string": "off",
    },
  },
  {
    // diagram-js types its rule contexts, command contexts and event payloads as `any`; the
    // editor's glue to it names the types it reads in each handler's signature instead.
    files: ["src/editor/core/**", "src/editor/features/**"],
    rules: UNSAFE_ANY_RULES,
  },
  {
    // The tests break documents on purpose through `any`, and read diagram-js's untyped shapes.
    files: ["test/**"],
    rules: { ...UNSAFE_ANY_RULES, "@typescript-eslint/no-explicit-any": "off" },
  },
  {
    // Plain JavaScript (the build script, Node tools) has no types to check against.
    files: ["**/*.js", "**/*.mjs"],
    extends: [tseslint.configs.disableTypeChecked],
    languageOptions: { globals: { console: "readonly", process: "readonly" } },
  },
);
