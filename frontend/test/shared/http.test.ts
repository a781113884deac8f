import { afterEach, beforeEach, describe, expect, it, vi } from "vitest";

import { ApiError, csrfToken, getJson, postJson, refusalMessage, request } from "../../src/shared/http";

function answer(status: number, body: string, contentType = "application/json"): Response {
  return new Response(body, { status, headers: { "Content-Type": contentType } });
}

describe("the HTTP client", () => {
  const fetchMock = vi.fn<typeof fetch>();

  beforeEach(() => {
    vi.stubGlobal("fetch", fetchMock);
    document.cookie = "csrftoken=cookie-token; path=/";
  });

  afterEach(() => {
    vi.unstubAllGlobals();
    fetchMock.mockReset();
    document.cookie = "csrftoken=; expires=Thu, 01 Jan 1970 00:00:00 GMT; path=/";
    document.head.replaceChildren();
  });

  function sent(): { url: string; init: RequestInit; headers: Record<string, string> } {
    const [url, init] = fetchMock.mock.calls[0];
    return { url: String(url), init: init ?? {}, headers: (init?.headers ?? {}) as Record<string, string> };
  }

  it("posts JSON with the session's CSRF token and answers the JSON", async () => {
    fetchMock.mockResolvedValue(answer(201, '{"id": 7}'));
    await expect(postJson("/api/things/", { name: "a" })).resolves.toEqual({ id: 7 });
    const { url, init, headers } = sent();
    expect(url).toBe("/api/things/");
    expect(init.method).toBe("POST");
    expect(init.credentials).toBe("same-origin");
    expect(init.body).toBe('{"name":"a"}');
    expect(headers["X-CSRFToken"]).toBe("cookie-token");
    expect(headers["Content-Type"]).toBe("application/json");
  });

  it("takes the page's csrf-token meta when there is no cookie", () => {
    document.cookie = "csrftoken=; expires=Thu, 01 Jan 1970 00:00:00 GMT; path=/";
    const meta = document.createElement("meta");
    meta.name = "csrf-token";
    meta.content = "meta-token";
    document.head.append(meta);
    expect(csrfToken()).toBe("meta-token");
  });

  it("sends no CSRF token and no body with a GET", async () => {
    fetchMock.mockResolvedValue(answer(200, "[1, 2]"));
    await expect(getJson("/api/list/")).resolves.toEqual([1, 2]);
    const { init, headers } = sent();
    expect(init.method).toBe("GET");
    expect(init.body).toBeUndefined();
    expect(headers["X-CSRFToken"]).toBeUndefined();
    expect(headers.Accept).toBe("application/json");
  });

  it("sends a string body as it is, typed as asked", async () => {
    fetchMock.mockResolvedValue(answer(200, "{}"));
    await request("POST", "/api/import/", "<pnml/>", "application/xml");
    const { init, headers } = sent();
    expect(init.body).toBe("<pnml/>");
    expect(headers["Content-Type"]).toBe("application/xml");
  });

  it("answers null for an empty body", async () => {
    fetchMock.mockResolvedValue(new Response(null, { status: 204 }));
    await expect(request("DELETE", "/api/things/7/")).resolves.toBeNull();
  });

  it("turns the API's refusal into an ApiError with its status, detail and field errors", async () => {
    const body = { detail: "Invalid input: count: must be a number.", fields: { count: ["must be a number."] } };
    fetchMock.mockResolvedValue(answer(400, JSON.stringify(body)));
    const error = await postJson("/api/work-items/3/complete/", {}).catch((e: unknown) => e);
    expect(error).toBeInstanceOf(ApiError);
    const refusal = error as ApiError;
    expect(refusal.status).toBe(400);
    expect(refusal.message).toBe("Invalid input: count: must be a number.");
    expect(refusal.fields).toEqual({ count: ["must be a number."] });
    expect(refusal.body).toEqual(body);
  });

  it("keeps a refusal's status when its body is not JSON", async () => {
    fetchMock.mockResolvedValue(answer(502, "<html>Bad gateway</html>", "text/html"));
    const error = (await getJson("/api/cases/1/").catch((e: unknown) => e)) as ApiError;
    expect(error).toBeInstanceOf(ApiError);
    expect(error.status).toBe(502);
    expect(error.message).toBe("The server answered 502.");
    expect(error.fields).toEqual({});
    expect(error.body).toBeNull();
  });

  it("refuses a 200 answer that is not JSON (a sign-in page)", async () => {
    fetchMock.mockResolvedValue(answer(200, "<html>Sign in</html>", "text/html"));
    const error = (await getJson("/api/cases/1/").catch((e: unknown) => e)) as ApiError;
    expect(error).toBeInstanceOf(ApiError);
    expect(error.status).toBe(200);
  });

  it("says the server cannot be reached when the request never arrives", async () => {
    fetchMock.mockRejectedValue(new TypeError("Failed to fetch"));
    const error = (await getJson("/api/cases/1/").catch((e: unknown) => e)) as ApiError;
    expect(error).toBeInstanceOf(ApiError);
    expect(error.status).toBe(0);
    expect(error.message).toBe("The server cannot be reached.");
  });
});

describe("a refusal's message", () => {
  it("says a field error once, when the detail already says it", () => {
    const body = { detail: "Invalid input: name: This field may not be blank.", fields: { name: ["This field may not be blank."] } };
    expect(refusalMessage(400, body)).toBe("Invalid input: name: This field may not be blank.");
  });

  it("adds the field errors the detail does not say", () => {
    expect(refusalMessage(400, { detail: "The answers are not valid.", fields: { count: "must be a number." } })).toBe(
      "The answers are not valid. count: must be a number.",
    );
  });

  it("takes no other key of a refusal with a detail for a field", () => {
    expect(refusalMessage(409, { detail: "The cobot is busy.", code: "busy" })).toBe("The cobot is busy.");
  });
});
