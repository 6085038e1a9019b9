// Runs a Flamenco job compiler script outside Flamenco, for the tests.
//
//   node tests/flamenco_harness.js SCRIPT.js job-type     prints JOB_TYPE as JSON
//   node tests/flamenco_harness.js SCRIPT.js compile      reads a job as JSON on
//                                                         stdin, prints the tasks
//
// Flamenco Manager loads job scripts into an embedded VM as plain scripts (not
// modules), in strict mode, with a handful of globals. This does the same with
// Node's `vm` module: the script text runs in a fresh context whose only
// globals are stand-ins for Flamenco's `author`, `print`, `alert` and
// `formatTimestampLocal`. A script that reaches for anything else (require,
// console, process, ...) fails here as it would on the Manager.
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
    const task = {
        id: `task-${nextTaskId++}`,
        name: name,
        type: type,
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
                if (!other || typeof other.id !== "string") {
                    throw new Error("task.addDependency: not a task from author.Task()");
                }
                task.dependencies.push(other.id);
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

// Flamenco's formatTimestampLocal: local time as YYYY-MM-DD_HHMMSS.
function formatTimestampLocal(date) {
    const pad = (n) => String(n).padStart(2, "0");
    return `${date.getFullYear()}-${pad(date.getMonth() + 1)}-${pad(date.getDate())}` +
        `_${pad(date.getHours())}${pad(date.getMinutes())}${pad(date.getSeconds())}`;
}

function makeJob(spec) {
    const tasks = [];
    return {
        job: {
            name: spec.name || "test job",
            type: spec.type || "solidwire",
            priority: spec.priority === undefined ? 50 : spec.priority,
            created: new Date(spec.created || "2024-01-02T03:04:05Z"),
            settings: Object.assign({}, spec.settings || {}),
            metadata: Object.assign({}, spec.metadata || {}),
            addTask(task) {
                if (!task || typeof task.addCommand !== "function" || typeof task.id !== "string") {
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
        author: { Task: makeTask, Command: makeCommand },
        print: (...args) => log.push(args.map(String).join(" ")),
        alert: (...args) => log.push(args.map(String).join(" ")),
        formatTimestampLocal: formatTimestampLocal,
    });
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
    if (!scriptPath || ["job-type", "compile"].indexOf(action) < 0) {
        fail("usage: flamenco_harness.js SCRIPT.js job-type|compile  (job JSON on stdin for compile)");
    }
    const { context, log } = loadScript(scriptPath);

    if (action === "job-type") {
        const jobType = globalValue(context, "JOB_TYPE");
        if (jobType === undefined) {
            fail("the script defines no JOB_TYPE");
        }
        process.stdout.write(JSON.stringify(jobType) + "\n");
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
