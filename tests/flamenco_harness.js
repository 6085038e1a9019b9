// Runs a Flamenco job compiler script outside Flamenco, for the tests.
//
//   node tests/flamenco_harness.js SCRIPT.js job-type     prints the job type as JSON
//   node tests/flamenco_harness.js SCRIPT.js compile      reads a job as JSON on
//                                                         stdin, prints the tasks
//
// It follows Flamenco Manager's job compiler (internal/manager/job_compilers
// in Flamenco 3.x), which runs each script in its own goja VM:
//   - the script is compiled as a plain script in strict mode;
//   - the globals beyond the language are exactly print, alert,
//     frameChunker, formatTimestampLocal, author (Task, Command), path
//     (basename, dirname, join, stem) and process (cwd, platform);
//   - Go values reach the script with their field names' first letter
//     lower-cased (goja's UncapFieldNameMapper): the job has name, jobType,
//     priority, status, created, settings, metadata, storage, tasks and
//     addTask(); a task has uUID, name, type, priority, commands,
//     dependencies, addCommand() and addDependency();
//   - job.created is a Go time.Time, not a JavaScript Date: only
//     formatTimestampLocal() reads it;
//   - the job type is named after the file ("my_type.js" -> "my-type").
// A script that reaches for anything else (require, console, Date methods on
// job.created, ...) fails here as it would on the Manager. What only a real
// Manager shows is listed in docs/dev/render-farm-checks.md.
//
// The stand-ins record what the script authors. Output is one JSON object:
//   {"ok": true, "tasks": [...], "settings": {...}}    compile succeeded
//   {"ok": false, "error": "message"}                   compileJob threw
// Harness problems (bad arguments, unreadable script) exit with status 2.

"use strict";

const fs = require("fs");
const vm = require("vm");

function fail(message) {
    process.stderr.write(`flamenco_harness: ${message}\n`);
    process.exit(2);
}

// ---- Stand-ins for Flamenco's globals -------------------------------------

let nextTaskId = 1;

// author.Task(name, type): Flamenco trims both and refuses empty ones.
function makeTask(name, type) {
    name = String(name === undefined ? "" : name).trim();
    type = String(type === undefined ? "" : type).trim();
    if (!name) {
        throw new Error("author.Task(name, type): name is required");
    }
    if (!type) {
        throw new Error("author.Task(name, type): type is required");
    }
    // Field names as goja maps Go's AuthoredTask (UUID -> uUID); priority 50
    // is what Flamenco gives every authored task.
    const task = {
        uUID: `00000000-0000-4000-8000-${String(nextTaskId++).padStart(12, "0")}`,
        name: name,
        type: type,
        priority: 50,
        commands: [],
        dependencies: [],
    };
    // Non-enumerable methods, so the recorded task prints as plain data.
    Object.defineProperties(task, {
        addCommand: {
            value(command) {
                if (!command || typeof command.name !== "string") {
                    throw new Error("task.addCommand: not a command from author.Command()");
                }
                task.commands.push(command);
            },
        },
        addDependency: {
            value(other) {
                if (!other || typeof other.uUID !== "string") {
                    throw new Error("task.addDependency: not a task from author.Task()");
                }
                task.dependencies.push(other.uUID);
            },
        },
    });
    return task;
}

// author.Command(name, parameters, totalStepCount): parameters are passed on to
// the Worker as JSON, so they must survive a JSON round trip.
function makeCommand(name, parameters, totalStepCount) {
    if (typeof name !== "string" || !name) {
        throw new Error("author.Command(name, parameters): name is required");
    }
    return {
        name: name,
        parameters: JSON.parse(JSON.stringify(parameters === undefined ? {} : parameters)),
        totalStepCount: totalStepCount === undefined ? 0 : totalStepCount,
    };
}

// job.created: a Go time.Time on the Manager, which a script can only hand to
// formatTimestampLocal. An opaque object here, so a script that treats it as
// a Date fails here too.
const GO_TIME = new WeakMap();

function goTime(date) {
    const value = Object.freeze(Object.create(null));
    GO_TIME.set(value, date);
    return value;
}

// Flamenco's formatTimestampLocal: local time as YYYY-MM-DD_HHMMSS (Go's
// "2006-01-02_150405").
function formatTimestampLocal(timestamp) {
    const date = GO_TIME.get(timestamp);
    if (date === undefined) {
        throw new TypeError("formatTimestampLocal: not a time from the job (job.created)");
    }
    const pad = (n) => String(n).padStart(2, "0");
    return `${date.getFullYear()}-${pad(date.getMonth() + 1)}-${pad(date.getDate())}` +
        `_${pad(date.getHours())}${pad(date.getMinutes())}${pad(date.getSeconds())}`;
}

// Flamenco's frameChunker(frameRange, chunkSize): "1..10,20-25,40" -> chunks
// of at most chunkSize frames, each merged back into "A-B" runs (two frames in
// a row are written "A,B"). Frames are deduplicated and sorted; "-" and ".."
// both mean a range, so negative frames cannot be written.
function frameChunker(frameRange, chunkSize) {
    frameRange = String(frameRange).trim();
    if (!frameRange) {
        throw new Error(`invalid range "${frameRange}": empty range`);
    }
    if (!(chunkSize >= 1)) {
        throw new Error(`invalid chunk size, must be positive number: ${chunkSize}`);
    }
    const seen = new Set();
    const text = frameRange.split("..").join("-");
    for (const part of text.split(",")) {
        const ends = part.split("-");
        const parse = (s) => {
            if (!/^\s*[+-]?\d+\s*$/.test(s)) {
                throw new Error(`invalid range "${text}": ${part}`);
            }
            return parseInt(s, 10);
        };
        if (ends.length === 1) {
            seen.add(parse(ends[0]));
        } else if (ends.length === 2) {
            const first = parse(ends[0]);
            const last = parse(ends[1]);
            for (let frame = first; frame <= last; frame++) {
                seen.add(frame);
            }
        } else {
            throw new Error(`invalid range "${text}": ${part}`);
        }
    }
    const frames = Array.from(seen).sort((a, b) => a - b);
    if (frames.length === 0) {
        throw new Error(`invalid range "${frameRange}": empty range`);
    }
    const chunks = [];
    for (let i = 0; i < frames.length; i += chunkSize) {
        chunks.push(mergeFrames(frames.slice(i, i + chunkSize)));
    }
    return chunks;
}

function mergeFrames(frames) {
    const ranges = [];
    const append = (from, to) => {
        if (from === to) {
            ranges.push(`${from}`);
        } else if (from + 1 === to) {
            ranges.push(`${from}`, `${to}`);
        } else {
            ranges.push(`${from}-${to}`);
        }
    };
    let start = frames[0];
    let previous = frames[0];
    for (const frame of frames) {
        if (frame > previous + 1) {
            append(start, previous);
            start = frame;
        }
        previous = frame;
    }
    append(start, previous);
    return ranges.join(",");
}

// Flamenco's `path` module (its crosspath package: forward slashes, any
// platform's paths).
const crosspath = {
    basename(p) {
        const parts = String(p).replace(/\\/g, "/").replace(/\/+$/, "").split("/");
        return parts[parts.length - 1] || (String(p).startsWith("/") ? "/" : ".");
    },
    dirname(p) {
        const text = String(p).replace(/\\/g, "/");
        const index = text.lastIndexOf("/");
        return index < 0 ? "." : index === 0 ? "/" : text.slice(0, index);
    },
    join(...parts) {
        return parts.filter((part) => part !== "").join("/").replace(/\/+/g, "/");
    },
    stem(p) {
        const base = crosspath.basename(p);
        const dot = base.lastIndexOf(".");
        return dot > 0 ? base.slice(0, dot) : base;
    },
};

function jobTypeName(scriptPath) {
    const file = scriptPath.replace(/\\/g, "/").split("/").pop();
    return file.replace(/\.[^.]*$/, "").replace(/_/g, "-");
}

function makeJob(spec) {
    const tasks = [];
    return {
        // Field names as goja maps Go's AuthoredJob.
        job: {
            jobID: "00000000-0000-4000-8000-000000000001",
            workerTagUUID: spec.worker_tag || "",
            name: spec.name || "test job",
            jobType: spec.type || "solidwire",
            priority: spec.priority === undefined ? 50 : spec.priority,
            status: "under-construction",
            created: goTime(new Date(spec.created || "2024-01-02T03:04:05Z")),
            // The submitted JSON as Go decodes it: numbers are numbers,
            // strings strings; nothing is checked against JOB_TYPE.
            settings: Object.assign({}, spec.settings || {}),
            metadata: Object.assign({}, spec.metadata || {}),
            storage: { shamanCheckoutID: "" },
            tasks: tasks,
            addTask(task) {
                if (!task || typeof task.addCommand !== "function" || typeof task.uUID !== "string") {
                    throw new Error("job.addTask: not a task from author.Task()");
                }
                tasks.push(task);
            },
        },
        tasks: tasks,
    };
}

// ---- Loading the script ----------------------------------------------------

function loadScript(scriptPath) {
    let text;
    try {
        text = fs.readFileSync(scriptPath, "utf8");
    } catch (err) {
        fail(`cannot read ${scriptPath}: ${err.message}`);
    }
    const log = [];
    const context = vm.createContext({
        print: (...args) => log.push(args.map(String).join(" ")),
        alert: (...args) => log.push(args.map(String).join(" ")),
        frameChunker: frameChunker,
        formatTimestampLocal: formatTimestampLocal,
        author: { Task: makeTask, Command: makeCommand },
        path: crosspath,
        process: { cwd: () => "/flamenco-manager", platform: "linux" },
    });
    // V8 gives every context a few globals goja does not have.
    vm.runInContext("delete globalThis.console; delete globalThis.WebAssembly;", context);
    // Flamenco compiles scripts in strict mode. The directive goes on the
    // first line so error line numbers still match the file.
    vm.runInContext(`"use strict"; ${text}`, context, { filename: scriptPath });
    return { context: context, log: log };
}

// Top-level `const` lives in the context's global lexical scope, not on the
// global object, so it is read back by evaluating its name in the context.
function globalValue(context, name) {
    return vm.runInContext(`typeof ${name} === "undefined" ? undefined : ${name}`, context);
}

function main() {
    const [scriptPath, action] = process.argv.slice(2);
    if (action === "frame-chunker") {
        // Flamenco's own chunking, for comparing a script's against it:
        // {"frames": "1-10", "chunk_size": 3} on stdin.
        const request = JSON.parse(fs.readFileSync(0, "utf8"));
        process.stdout.write(JSON.stringify(frameChunker(request.frames, request.chunk_size)) + "\n");
        return;
    }
    if (!scriptPath || ["job-type", "compile"].indexOf(action) < 0) {
        fail("usage: flamenco_harness.js SCRIPT.js job-type|compile|frame-chunker  (JSON on stdin for compile)");
    }
    const { context, log } = loadScript(scriptPath);

    if (action === "job-type") {
        const jobType = globalValue(context, "JOB_TYPE");
        if (jobType === undefined) {
            fail("the script defines no JOB_TYPE");
        }
        // As the Manager lists it (AvailableJobType): JOB_TYPE and its name.
        process.stdout.write(JSON.stringify(Object.assign({ name: jobTypeName(scriptPath) }, jobType)) + "\n");
        return;
    }

    let spec;
    try {
        spec = JSON.parse(fs.readFileSync(0, "utf8"));
    } catch (err) {
        fail(`stdin is not a JSON job: ${err.message}`);
    }
    const compileJob = globalValue(context, "compileJob");
    if (typeof compileJob !== "function") {
        fail("the script defines no compileJob(job) function");
    }
    const { job, tasks } = makeJob(spec);
    let result;
    try {
        compileJob(job);
        result = { ok: true, tasks: tasks, settings: job.settings, log: log };
    } catch (err) {
        // Errors thrown inside the vm context are not `instanceof Error` here,
        // so read the message duck-typed.
        const message = err && typeof err.message === "string" ? err.message : String(err);
        result = { ok: false, error: message, errorIsError: !!(err && err.name === "Error"), log: log };
    }
    process.stdout.write(JSON.stringify(result) + "\n");
}

main();
