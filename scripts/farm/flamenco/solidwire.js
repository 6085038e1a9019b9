// SPDX-License-Identifier: GPL-3.0-or-later
//
// Flamenco 3.x job type: render a .blend with the SolidWire extension.
//
// Install: copy this file into the `scripts` folder next to the
// flamenco-manager executable (the job type is named after the file:
// "solidwire"). See docs/user/render-farm.md.
//
// Two modes:
//   SOLIDWIRE  Blender's own animation render with the SolidWire engine:
//                blender -b FILE -E SOLIDWIRE -o OUTPUT -s START -e END -j 1 -a
//   WIRE_OVER  the extension's command line, which renders the image
//              underneath with another engine and composites the wire over it:
//                blender -c solidwire render FILE -o OUTPUT.EXT -s START -e END -j 1 -a
//                        --over ENGINE [--preset NAME] --progress json
//              SOLIDWIRE mode also takes this form when a preset is given,
//              because only the extension's command line can apply one.
//
// Flamenco runs this file as a plain script (not a module) in strict mode, in
// an embedded JavaScript VM (goja) that is not Node: the only globals beyond
// the language are the ones Flamenco provides. This file uses `author`,
// `print` and `formatTimestampLocal` and nothing else, and sticks to syntax
// the bundled job types also use (no `?.` or `??`).

const JOB_TYPE = {
    label: "SolidWire Render",
    settings: [
        // Chosen by the artist when submitting.
        {
            key: "frames", type: "string", required: true,
            eval: "f'{C.scene.frame_start}-{C.scene.frame_end}'",
            evalInfo: { showLinkButton: true, description: "Scene frame range" },
            description: "Frames to render, e.g. '1-100', '1-10,20-30' or '47'",
        },
        {
            // SolidWire frames take well under a second, so Blender's start-up
            // (seconds) dominates a one-frame task; ten frames a task keeps the
            // farm busy rendering rather than starting Blender.
            key: "chunk_size", type: "int32", default: 10, propargs: { min: 1 },
            description: "Number of frames one task renders (one Blender start per task)",
            visible: "submission",
        },
        {
            key: "mode", type: "string", required: true, default: "SOLIDWIRE",
            choices: ["SOLIDWIRE", "WIRE_OVER"],
            description: "SOLIDWIRE: render with the SolidWire engine. " +
                "WIRE_OVER: render with another engine and composite the wire over it, frame by frame",
        },
        {
            key: "over_engine", type: "string", default: "SCENE",
            choices: ["SCENE", "CYCLES", "BLENDER_EEVEE", "BLENDER_WORKBENCH"],
            description: "WIRE_OVER only: engine of the image underneath the wire (SCENE: the scene's own engine)",
        },
        {
            key: "preset", type: "string", default: "",
            description: "Optional SolidWire preset (a name or a preset file) applied before rendering",
        },

        // render_output_root + add_path_components give render_output_path,
        // the same way Flamenco's own Blender job type builds it, so output
        // lands where a Flamenco user expects it.
        {
            key: "render_output_root", type: "string", subtype: "dir_path", required: true,
            visible: "submission",
            description: "Folder under which the job's frames are written (job name and timestamp are added)",
        },
        {
            key: "add_path_components", type: "int32", required: true, default: 0,
            propargs: { min: 0, max: 32 }, visible: "submission",
            description: "How many folder names of the blend file's path to repeat under the output root",
        },
        {
            key: "render_output_path", type: "string", subtype: "file_path", editable: false,
            eval: "str(Path(abspath(settings.render_output_root), last_n_dir_parts(settings.add_path_components), jobname, '{timestamp}', '######'))",
            description: "Where the frames are written; ###### becomes the frame number",
        },

        // Filled in from the scene at submission.
        { key: "blendfile", type: "string", required: true, visible: "web",
          description: "The .blend file to render" },
        { key: "format", type: "string", eval: "C.scene.render.image_settings.file_format", visible: "web",
          description: "Image format of the frames (the scene's; Wire Over and preset jobs take PNG, JPEG, TIFF, OpenEXR, WebP or BMP)" },
    ],
};

const MODES = ["SOLIDWIRE", "WIRE_OVER"];
const OVER_ENGINES = ["SCENE", "CYCLES", "BLENDER_EEVEE", "BLENDER_WORKBENCH"];

// Chunks become separate Blender runs writing separate images; a movie file
// cannot be assembled that way.
const VIDEO_FORMATS = ["FFMPEG", "AVI_RAW", "AVI_JPEG"];

// The extension's command line picks the image format from the file
// extension of -o and refuses a path without one, while Flamenco's output
// path ends in "######". These are the formats it writes, by the scene's
// file_format. A multilayer scene keeps its passes in ".exr" with a preset;
// a Wire Over composite is one image, so there it is a single-layer EXR.
const CLI_EXTENSIONS = {
    PNG: ".png",
    JPEG: ".jpg",
    TIFF: ".tif",
    OPEN_EXR: ".exr",
    OPEN_EXR_MULTILAYER: ".exr",
    WEBP: ".webp",
    BMP: ".bmp",
};

// Blender's largest frame number (MAXFRAME). Also keeps a typo such as
// "1-10000000000" from making the Manager build a huge frame list.
const MAX_FRAME = 1048574;


function compileJob(job) {
    const settings = job.settings;
    const plan = checkSettings(settings);

    let renderOutput = renderOutputPath(job);
    if (plan.useCli) {
        renderOutput = withImageExtension(renderOutput, plan.cliExtension);
    }
    // Store the path actually used so the job shows where its frames went.
    settings.render_output_path = renderOutput;

    const chunks = chunkFrames(plan.frames, plan.chunkSize);
    print("SolidWire job:", plan.mode, "frames", settings.frames, "in", chunks.length, "tasks");

    for (const chunk of chunks) {
        // Task type "blender": workers that run Blender run these. A worker
        // without the extension fails its tasks loudly (see docs), and
        // Flamenco's per-job blocklist then stops sending it more.
        const task = author.Task(`render-${chunkLabel(chunk)}`, "blender");
        // -s/-e describe one unbroken range, so a chunk that spans a gap in
        // the frame list ("4-5,8") gets one command per run of frames.
        for (const run of chunk) {
            task.addCommand(renderCommand(settings, plan, renderOutput, run));
        }
        job.addTask(task);
    }
}


// Validates the settings a job was submitted with and returns the parsed
// values. Throws an Error with a one-line message, which Flamenco shows to
// whoever submitted the job.
function checkSettings(settings) {
    const mode = String(settingOrDefault(settings, "mode")).trim().toUpperCase();
    if (MODES.indexOf(mode) < 0) {
        throw new Error(`mode must be one of ${MODES.join(", ")}, not ${quote(settings.mode)}`);
    }

    const overEngine = String(settingOrDefault(settings, "over_engine")).trim().toUpperCase();
    if (OVER_ENGINES.indexOf(overEngine) < 0) {
        throw new Error(`over_engine must be one of ${OVER_ENGINES.join(", ")}, not ${quote(settings.over_engine)}`);
    }

    const chunkSize = Number(settingOrDefault(settings, "chunk_size"));
    if (!Number.isInteger(chunkSize) || chunkSize < 1) {
        throw new Error(`chunk_size must be a whole number of at least 1, not ${quote(settings.chunk_size)}`);
    }

    const preset = String(settingOrDefault(settings, "preset")).trim();
    // The preset is handed over as one argument (no shell involved), but a
    // leading "-" would still be read as an option by the command line.
    if (preset.charAt(0) === "-" || /[\u0000-\u001f]/.test(preset)) {
        throw new Error(`preset ${quote(preset)} is not a usable preset name or file`);
    }

    if (!settings.blendfile || !String(settings.blendfile).trim()) {
        throw new Error("blendfile is empty; give the .blend file to render");
    }

    const format = String(settings.format || "").trim().toUpperCase();
    if (VIDEO_FORMATS.indexOf(format) >= 0) {
        throw new Error(`format ${quote(format)} is a movie; SolidWire farm jobs render image sequences (set an image format)`);
    }

    // Only the extension's command line can apply a preset.
    const useCli = mode === "WIRE_OVER" || preset !== "";
    let cliExtension = "";
    if (useCli) {
        // A job submitted without a format (through the API) gets PNG, the
        // command line's most common choice.
        cliExtension = CLI_EXTENSIONS[format || "PNG"];
        if (!cliExtension) {
            throw new Error(`format ${quote(format)} is not one the SolidWire command line writes (Wire Over and ` +
                "preset jobs): use PNG, JPEG, TIFF, OPEN_EXR, WEBP or BMP");
        }
    }

    return {
        mode: mode,
        overEngine: overEngine,
        chunkSize: chunkSize,
        preset: preset,
        useCli: useCli,
        cliExtension: cliExtension,
        frames: parseFrames(settings.frames),
    };
}

// Quotes a submitted value for an error message. JSON escaping keeps the
// message on one line whatever the value holds (Flamenco shows it as is).
function quote(value) {
    return JSON.stringify(String(value));
}

// A missing setting takes the default declared in JOB_TYPE. The Blender
// add-on always sends every setting, but jobs submitted through the API or a
// script need not, and the defaults should live in one place.
function settingOrDefault(settings, key) {
    const value = settings[key];
    if (value !== undefined && value !== null && value !== "") {
        return value;
    }
    for (const setting of JOB_TYPE.settings) {
        if (setting.key === key && setting.default !== undefined) {
            return setting.default;
        }
    }
    return value === undefined || value === null ? "" : value;
}


// "1-10, 20..30,47" -> sorted list of distinct frame numbers. Accepts both
// "A-B" and Blender's "A..B" the way Flamenco's own frame chunker does.
function parseFrames(frames) {
    const text = String(frames === undefined || frames === null ? "" : frames).trim();
    if (!text) {
        throw new Error("frames is empty; give frames like '1-100', '1-10,20-30' or '47'");
    }

    const seen = {};
    const list = [];
    for (const rawPart of text.split(",")) {
        const part = rawPart.trim();
        // Negative frames are refused on purpose: Blender reads a negative
        // -s/-e value as relative to the scene's range, not as frame -5.
        const match = /^(\d+)(?:\s*(?:-|\.\.)\s*(\d+))?$/.exec(part);
        if (!match) {
            throw new Error(`frames: cannot read ${quote(part)} in ${quote(text)}; use N, A-B or A..B separated by commas`);
        }
        const first = parseInt(match[1], 10);
        const last = match[2] === undefined ? first : parseInt(match[2], 10);
        if (last < first) {
            throw new Error(`frames: range ${quote(part)} runs backwards; write it as ${last}-${first}`);
        }
        if (last > MAX_FRAME) {
            throw new Error(`frames: ${last} is past Blender's last frame (${MAX_FRAME})`);
        }
        for (let frame = first; frame <= last; frame++) {
            if (!seen[frame]) {
                seen[frame] = true;
                list.push(frame);
            }
        }
    }
    list.sort(function (a, b) { return a - b; });
    return list;
}

// Splits the frame list into chunks of `chunkSize` frames (the last one may
// be shorter), counting frames rather than range ends so every task does the
// same amount of work even when the list has gaps. Each chunk is a list of
// runs {start, end} of consecutive frames.
function chunkFrames(frameList, chunkSize) {
    const chunks = [];
    for (let i = 0; i < frameList.length; i += chunkSize) {
        const frames = frameList.slice(i, i + chunkSize);
        const runs = [];
        for (const frame of frames) {
            const last = runs[runs.length - 1];
            if (last && frame === last.end + 1) {
                last.end = frame;
            } else {
                runs.push({ start: frame, end: frame });
            }
        }
        chunks.push(runs);
    }
    return chunks;
}

// "1-10", "8", "4-5,8": used in task names, like Flamenco's "render-1-10".
function chunkLabel(runs) {
    return runs.map(function (run) {
        return run.start === run.end ? `${run.start}` : `${run.start}-${run.end}`;
    }).join(",");
}


// FRAME_STEP_NOTE: both forms pass "-j 1". The job's frame list already says
// which frames to render, but Blender's -a and the extension's range both step
// by the scene's frame step, so a scene saved with a step of 2 would otherwise
// skip every other frame of each chunk.
//
// Both forms use Flamenco's "blender-render" command rather than "exec": it
// builds `{exe} {exeArgs} {argsBefore} {blendfile} {args}`, which fits both
// (`-c solidwire render` goes in argsBefore, before the file), and it keeps
// what "exec" would lose: the Manager's `{blender}` executable and
// `{blenderArgs}` per-platform settings, and the Worker's parsing of Blender's
// output for progress and preview images.
function renderCommand(settings, plan, renderOutput, run) {
    if (!plan.useCli) {
        return author.Command("blender-render", {
            exe: "{blender}",
            exeArgs: "{blenderArgs}",
            // -b is normally in {blenderArgs} already; repeating it is
            // harmless and keeps a Manager configured without it from
            // opening a Blender window on the worker.
            argsBefore: ["-b"],
            blendfile: settings.blendfile,
            // Blender applies these in order after loading the file, so the
            // engine, output and range come before -a, which renders. -E also
            // makes a worker without the extension fail ("engine not found")
            // instead of quietly rendering with a fallback engine.
            args: [
                "-E", "SOLIDWIRE",
                "-o", renderOutput,
                "-s", `${run.start}`,
                "-e", `${run.end}`,
                "-j", "1",  // see FRAME_STEP_NOTE
                "-a",
            ],
        });
    }

    // The extension's command line. `-c` implies background mode and hands
    // every argument after the command name to the extension, so the
    // extension's own options follow the file.
    const args = [
        "-o", renderOutput,
        "-s", `${run.start}`,
        "-e", `${run.end}`,
        "-j", "1",  // see FRAME_STEP_NOTE
        // Ask for the whole range explicitly rather than rely on -s/-e
        // implying it.
        "-a",
    ];
    if (plan.mode === "WIRE_OVER") {
        // Always named, SCENE included: without --over the command renders
        // plain SolidWire.
        args.push("--over", plan.overEngine);
    }
    if (plan.preset !== "") {
        args.push("--preset", plan.preset);
    }
    // One JSON line per finished frame in the task log: machine-readable
    // for anyone post-processing logs, and it does not disturb the Worker's
    // own parsing of Blender's output.
    args.push("--progress", "json");

    return author.Command("blender-render", {
        exe: "{blender}",
        exeArgs: "{blenderArgs}",
        argsBefore: ["-c", "solidwire", "render"],
        blendfile: settings.blendfile,
        args: args,
    });
}


// Expands "{timestamp}" in the output path (put there by the setting's eval)
// to the job's creation time, the same substitution Flamenco's own Blender
// job type does. Other {...} fields are left for the Manager's variables.
function renderOutputPath(job) {
    const outputPath = job.settings.render_output_path;
    if (!outputPath || !String(outputPath).trim()) {
        throw new Error("render_output_path is empty; set render_output_root when submitting");
    }
    return String(outputPath).replace(/{([^}]+)}/g, function (match, name) {
        return name === "timestamp" ? formatTimestampLocal(job.created) : match;
    });
}

// Appends the image extension the command line needs, unless the path already
// ends in one it knows (someone may have typed "frame_####.png" themselves).
function withImageExtension(outputPath, extension) {
    const known = [".png", ".jpg", ".jpeg", ".tif", ".tiff", ".exr", ".bmp", ".webp"];
    const lower = outputPath.toLowerCase();
    for (const ext of known) {
        if (lower.length > ext.length && lower.slice(-ext.length) === ext) {
            return outputPath;
        }
    }
    return outputPath + extension;
}
