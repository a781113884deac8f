/**
 * Where JSON text first goes wrong. Browsers' JSON.parse messages differ and
 * some no longer give a position, so the editor finds it itself to tell an
 * engineer the line and column of a broken file.
 */

export interface JsonProblem {
  line: number;
  column: number;
  /** What was found there: a character in quotes, or "the end of the file". */
  found: string;
}

/** The first syntax error in text, or null when it is valid JSON. */
export function jsonProblem(text: string): JsonProblem | null {
  const scanner = new Scanner(text);
  try {
    scanner.skip();
    scanner.value();
    scanner.skip();
    if (scanner.at < text.length) throw scanner.error();
    return null;
  } catch (error) {
    if (!(error instanceof SyntaxProblem)) throw error;
    const before = text.slice(0, error.at);
    const line = before.split("\n").length;
    const column = error.at - (before.lastIndexOf("\n") + 1) + 1;
    const found = error.at >= text.length ? "the end of the file" : `"${text[error.at]}"`;
    return { line, column, found };
  }
}

class SyntaxProblem extends Error {
  constructor(readonly at: number) {
    super(`JSON syntax error at ${at}`);
  }
}

class Scanner {
  at = 0;

  constructor(private readonly text: string) {}

  error(): SyntaxProblem {
    return new SyntaxProblem(this.at);
  }

  skip(): void {
    while (this.at < this.text.length && " \t\n\r".includes(this.text[this.at])) this.at += 1;
  }

  expect(char: string): void {
    if (this.text[this.at] !== char) throw this.error();
    this.at += 1;
  }

  value(): void {
    const char = this.text[this.at];
    if (char === "{") this.sequence("}", () => {
      this.string();
      this.skip();
      this.expect(":");
      this.skip();
      this.value();
    });
    else if (char === "[") this.sequence("]", () => this.value());
    else if (char === '"') this.string();
    else if (char !== undefined && "-0123456789".includes(char)) this.number();
    else {
      const word = ["true", "false", "null"].find((candidate) => this.text.startsWith(candidate, this.at));
      if (!word) throw this.error();
      this.at += word.length;
    }
  }

  sequence(close: string, item: () => void): void {
    this.at += 1;
    this.skip();
    if (this.text[this.at] === close) {
      this.at += 1;
      return;
    }
    for (;;) {
      item();
      this.skip();
      if (this.text[this.at] === close) {
        this.at += 1;
        return;
      }
      this.expect(",");
      this.skip();
    }
  }

  string(): void {
    this.expect('"');
    while (this.at < this.text.length && this.text[this.at] !== '"') {
      const char = this.text[this.at];
      if (char < " ") throw this.error();
      if (char === "\\") {
        this.at += 1;
        const escape = this.text[this.at];
        if (escape === "u") {
          if (!/^[0-9a-fA-F]{4}$/.test(this.text.slice(this.at + 1, this.at + 5))) throw this.error();
          this.at += 4;
        } else if (escape === undefined || !'"\\/bfnrt'.includes(escape)) throw this.error();
      }
      this.at += 1;
    }
    this.expect('"');
  }

  number(): void {
    const match = /^-?(0|[1-9]\d*)(\.\d+)?([eE][+-]?\d+)?/.exec(this.text.slice(this.at));
    if (!match || !match[0] || match[0] === "-") throw this.error();
    this.at += match[0].length;
  }
}
