import { defineConfig } from "vite";

// The page is built into the Python package (shipped as package data); no Node at run time.
export default defineConfig({
  base: "./",
  build: {
    outDir: "../src/spherewarp/viewer/static",
    emptyOutDir: true,
    assetsDir: "assets",
    target: "es2020",
  },
});
