#version 130
// Viewer insets: a quad covering the viewport, UV (0,0) at its bottom left.

in vec2 Corner;
out vec2 UV;

void main()
{
    UV = Corner;
    gl_Position = vec4(Corner * 2.0 - 1.0, 0.0, 1.0);
}
