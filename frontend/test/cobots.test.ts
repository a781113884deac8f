import { describe, expect, it } from "vitest";

import {
  commandBody,
  commandRow,
  doneText,
  question,
  registerText,
  stateFields,
  type CommandJson,
} from "../src/cobots/model";

function record(extra: Partial<CommandJson> = {}): CommandJson {
  return {
    id: 4,
    cobot: 1,
    command: "power-on",
    arguments: {},
    requested_by: "erin",
    requested_at: "2025-03-01T10:00:00Z",
    finished_at: "2025-03-01T10:00:02Z",
    outcome: "ok",
    message: "",
    ...extra,
  };
}

describe("the cobot page", () => {
  it("confirms every command and names the program of a load", () => {
    expect(commandBody("power-on", "Pick")).toEqual({ confirm: true });
    expect(commandBody("load-program", "Pick")).toEqual({ program: "Pick", confirm: true });
  });

  it("asks in words before it sends", () => {
    expect(question("power-on", "cobot1", "")).toBe("Power on cobot1?");
    expect(question("brake-release", "cobot1", "")).toBe("Release the brakes of cobot1?");
    expect(question("load-program", "cobot1", "Pick")).toBe("Load Pick on cobot1?");
  });

  it("shows a record row with who, what and what came of it", () => {
    const cells = commandRow(record({ command: "load-program", arguments: { program: "Pick" }, outcome: "refused", message: "busy" }));
    expect(cells.slice(1)).toEqual(["erin", "Load a program Pick", "Refused", "busy"]);
    expect(commandRow(record({ requested_by: null }))[1]).toBe("–");
    expect(doneText(record(), "cobot1")).toBe("Power on: cobot1 done.");
  });

  it("says why a cobot cannot be reached instead of its modes", () => {
    expect(stateFields({ reachable: false, error: "lost the gateway" })).toMatchObject({
      RobotMode: "–",
      error: "lost the gateway",
    });
    expect(stateFields({ reachable: true, RobotMode: "Running", LastError: "" })).toMatchObject({
      RobotMode: "Running",
      LastError: "–",
      error: "reachable",
    });
  });

  it("writes register values as the server does", () => {
    expect([true, 3, 0.25].map(registerText)).toEqual(["true", "3", "0.25"]);
  });
});
