pub mod tui_script;
