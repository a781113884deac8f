/**
 * Files: the draft is saved through the API (created on the first save of a
 * new pattern), published as a version, exported as hrc-pattern/1, PNML or
 * BPMN 2.0, and a file is imported as a new pattern. A file that cannot be
 * read changes nothing and says where it is wrong.
 */

import type CommandStack from "diagram-js/lib/command/CommandStack";
import type EventBus from "diagram-js/lib/core/EventBus";
import type Canvas from "diagram-js/lib/core/Canvas";
import type { Shape } from "diagram-js/lib/model/Types";

import type { Api } from "../../api";
import type PatternImporter from "../../core/PatternImporter";
import { objectOf, type RootObject } from "../../core/elements";
import { inspectFile } from "../../model/files";
import type PatternModeling from "../modeling/PatternModeling";

export type ExportFormat = "json" | "pnml" | "bpmn";

export interface FilesMessage {
  text: string;
  kind: "info" | "error";
  /** Where the message leads: the whole text becomes a link there. */
  href?: string;
}

/** A published version's page (the `patterns:version` URL). */
export function versionPage(id: number): string {
  return `/patterns/versions/${id}/`;
}

export default class PatternFiles {
  static $inject = ["eventBus", "config.api", "patternImporter", "config.pattern", "commandStack", "canvas", "modeling"];

  id: number | null;
  readonly organisation: number | undefined;
  dirty = false;
  busy = false;

  constructor(
    private readonly eventBus: EventBus,
    private readonly api: Api,
    private readonly importer: PatternImporter,
    pattern: { id: number | null; organisation?: number },
    commandStack: CommandStack,
    private readonly canvas: Canvas,
    private readonly modeling: PatternModeling,
  ) {
    this.id = pattern.id;
    this.organisation = pattern.organisation;
    eventBus.on("commandStack.changed", () => {
      this.dirty = commandStack.canUndo() || this.dirty;
      this.changed();
    });
    eventBus.on("import.done", () => {
      this.dirty = this.id === null;
      this.changed();
    });
  }

  get name(): string {
    const root = objectOf(this.canvas.getRootElement() as Shape) as RootObject | undefined;
    return String(root?.data.name ?? "");
  }

  rename(name: string): void {
    const trimmed = name.trim();
    if (!trimmed) throw new Error("A pattern needs a name.");
    if (trimmed !== this.name) this.modeling.updateData(this.canvas.getRootElement() as Shape, { name: trimmed });
  }

  /** Saves the draft; a new pattern is created first and the address becomes its edit page. */
  async save(): Promise<void> {
    await this.run("Saving…", async () => {
      const document = this.importer.document();
      const name = this.name || "New pattern";
      if (this.id === null) {
        const record = await this.api.createPattern(name, document, this.organisation);
        this.id = record.id;
        history.replaceState(null, "", `/patterns/${record.id}/edit/`);
      } else await this.api.savePattern(this.id, name, document);
      this.dirty = false;
      return "Saved.";
    });
  }

  async publish(): Promise<void> {
    if (this.dirty || this.id === null) await this.save();
    if (this.dirty || this.id === null) return;
    await this.run("Publishing…", async () => {
      const version = await this.api.publish(this.id as number);
      this.eventBus.fire("files.published", { version });
      return { text: `Published version ${version.number}.`, kind: "info", href: versionPage(version.id) };
    });
  }

  /** Imports a file as a new pattern and opens it; a refused file leaves everything as it was. */
  async importFile(file: File): Promise<void> {
    await this.run(`Importing ${file.name}…`, async () => {
      const inspected = inspectFile(file.name, await file.text());
      const record = await this.api.importFile(inspected.format, inspected.body, inspected.contentType, this.organisation);
      const address = `/patterns/${record.id}/edit/`;
      // Unsaved work here is never thrown away by an import: the new pattern waits to be opened.
      if (!this.dirty) window.location.assign(address);
      this.eventBus.fire("files.imported", { record, address });
      return `Imported ${file.name} as the new pattern “${record.name}”${this.dirty ? ": save this one, then open it from the list" : ""}.`;
    });
  }

  /** Saves unsaved changes, then downloads the draft in the format. */
  async exportAs(format: ExportFormat): Promise<void> {
    if (this.dirty || this.id === null) await this.save();
    if (this.dirty || this.id === null) return;
    const link = document.createElement("a");
    link.href = this.api.exportUrl(this.id, format);
    link.download = "";
    document.body.appendChild(link);
    link.click();
    link.remove();
  }

  private async run(pending: string, work: () => Promise<string | FilesMessage>): Promise<void> {
    this.busy = true;
    this.say({ text: pending, kind: "info" });
    try {
      const done = await work();
      this.say(typeof done === "string" ? { text: done, kind: "info" } : done);
    } catch (error) {
      this.say({ text: (error as Error).message, kind: "error" });
    } finally {
      this.busy = false;
      this.changed();
    }
  }

  private say(message: FilesMessage): void {
    this.eventBus.fire("files.message", message);
  }

  private changed(): void {
    this.eventBus.fire("files.changed", { dirty: this.dirty, id: this.id });
  }
}
